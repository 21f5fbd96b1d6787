"""The table of ``scripts/measure_changes.sh``: one row per ``hiper eval changes --json`` file
(named ``kb_SENSOR_SEED_DETECTOR.hiper.eval.json``), in markdown.

Usage: changes_table.py EVAL.json [EVAL.json ...]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

KINDS = ("moved", "removed", "added")
UNNAMED = ("picture", "shelf")  # classes of the sim neither detector names (not COCO classes)


def _row(path: Path) -> str:
    sensor, seed, detector = path.name.removeprefix("kb_").split(".")[0].rsplit("_", 2)
    doc = json.loads(path.read_text())
    later = [a for a in doc["alignment"] if a["method"] != "identity"]
    err_m = max((a["error_m"] for a in later), default=0.0)
    err_deg = max((a["error_deg"] for a in later), default=0.0)
    start_m = max((a.get("error_start_m", float("nan")) for a in later), default=0.0)
    path_m = max((a.get("error_path_max_m", float("nan")) for a in later), default=0.0)
    f1 = " | ".join(f"{doc['per_kind'][k]['f1']:.2f}" for k in KINDS)
    reid = doc["reid_precision"]
    ghost = doc["ghost_rate"]
    miscount = {c: v["error"] for c, v in doc["counts"].items() if v["error"] and c not in UNNAMED}
    return (f"| {seed} | {sensor} | {detector} | {err_m:.3f} / {start_m:.3f} / {path_m:.3f} / {err_deg:.2f} | "
            f"{f1} | "
            f"{'-' if reid is None else f'{reid:.2f}'} ({doc['reid_merged']}) | "
            f"{'-' if ghost is None else f'{ghost:.2f}'} ({doc['ghosts']}/{doc['present_real']}) | "
            f"{', '.join(f'{c} {e:+d}' for c, e in sorted(miscount.items())) or '0'} |")


def main(paths: list[Path]) -> None:
    print("| seed | sensor | detector | alignment error, worst: at the log's origin / start / along its path "
          "(m) / deg | F1 moved | F1 removed | F1 added "
          "| re-id precision (merged) | ghost rate (ghosts/present) "
          "| count error per class (last session; picture, shelf left out) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for path in sorted(paths, key=lambda p: p.name):
        print(_row(path))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: changes_table.py EVAL.json [EVAL.json ...]")
    main([Path(p) for p in sys.argv[1:]])
