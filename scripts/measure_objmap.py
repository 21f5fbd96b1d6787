"""Issue 53's table: perceive, export and score every log, one row per log.

Usage: python scripts/measure_objmap.py OUTDIR LOG [LOG ...] [-- perceive options]

Each LOG is a TUM-layout folder with gt/ (the shared worlds, `hiper sim` logs, `hiper convert`
copies). Runs `hiper perceive` (timed as a whole command), `hiper export --observations` and the
reference scorer (HIPER_WORLDS/../tools/eval_scene.py), then prints the figures issue 53 asks for:
classified precision, recall_nameable, recall_located, unknowns on nothing, static objects with a
stored speed above 0.05 m/s, duplicates (same-class predictions left unmatched on an object of that
class), walker speed error, background semantic precision, frames/s (wall clock: noisy on a
shared machine) and CPU ms per frame of the perceive command (user + system, all threads: under
2 × 1000 / 30 = 67 ms two free cores could keep 30 frames/s).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# the shared folder beside the checkout (../shared; a worktree in wt/: ../../shared)
SHARED = next((p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared") if p.is_dir()),
              ROOT.parent / "shared")
SCORER = Path(os.environ.get("HIPER_WORLDS", SHARED / "worlds")).parent / "tools" / "eval_scene.py"
PY = sys.executable


def hiper(*args: str) -> subprocess.CompletedProcess[str]:
    # -P: the checkout on PYTHONPATH, not the one in the current folder (``-m`` puts that first)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.setdefault("HIPER_MODELS", str(SHARED / "models"))
    return subprocess.run([PY, "-P", "-m", "hiper_cli", *args], capture_output=True, text=True, env=env,
                          check=False)


def frames(log: Path) -> int:
    lines = (log / "rgb.txt").read_text().splitlines()
    return sum(1 for line in lines if line.strip() and not line.startswith("#"))


def measure(out: Path, log: Path, extra: list[str]) -> dict[str, object]:
    name = log.name
    kb, export, metrics = out / f"{name}.hiper", out / f"{name}.json", out / f"{name}_m.json"
    start, cpu = time.monotonic(), resource.getrusage(resource.RUSAGE_CHILDREN)
    run = hiper("perceive", str(log), "--kb", str(kb), "--replace", *extra)
    wall_s = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = after.ru_utime + after.ru_stime - cpu.ru_utime - cpu.ru_stime
    (out / f"{name}.log").write_text(run.stdout + run.stderr)
    if run.returncode:
        return {"log": name, "error": (run.stdout + run.stderr).strip().splitlines()[-1]}
    hiper("export", str(export), "--kb", str(kb), "--observations")
    score = subprocess.run([PY, str(SCORER), str(log / "gt"), str(export), "--json", str(metrics)],
                           capture_output=True, text=True, check=False)
    (out / f"{name}_eval.txt").write_text(score.stdout + score.stderr)
    m = json.loads(metrics.read_text())
    fg, bg, sp = m["foreground"], m["background"], m["person_speed"]
    mis = fg["unmatched_breakdown"]
    unknowns = fg["unknown_predicted"]
    dup = sum(n for k, n in mis.items() if k.split("->")[0] == k.split("->")[1] != "unknown")
    inst = json.loads(export.read_text())["instances"]
    moving_static = sum(1 for i in inst if i["layer"] == "foreground"
                        and i.get("motion", i["state"]) == "static" and (i.get("speed_mps") or 0.0) > 0.05)
    return {"log": name, "prec_cls": fg["precision_classified"], "tp": fg["tp"],
            "fp_cls": fg["fp_classified"], "rec_name": fg["recall_nameable"],
            "n_name": fg["nameable_observed"], "rec_loc": fg["recall_located"],
            "unk_nothing": (mis.get("unknown->nothing", 0) / unknowns) if unknowns else None,
            "n_unk": unknowns, "static_speed": moving_static, "dup": dup,
            "walk_err": sp["mean_abs_error"], "bg_sem": bg["semantic_precision"],
            "fps": frames(log) / wall_s, "cpu_ms": 1000.0 * cpu_s / frames(log)}


def fmt(v: object) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.2f}" if v < 10 else f"{v:.1f}"
    return str(v)


def main() -> None:
    args = sys.argv[1:]
    extra: list[str] = []
    if "--" in args:
        extra = args[args.index("--") + 1:]
        args = args[: args.index("--")]
    out = Path(args[0])
    out.mkdir(parents=True, exist_ok=True)
    cols = ["log", "prec_cls", "tp", "fp_cls", "rec_name", "n_name", "rec_loc", "unk_nothing", "n_unk",
            "static_speed", "dup", "walk_err", "bg_sem", "fps", "cpu_ms"]
    rows = []
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for log in args[1:]:
        row = measure(out, Path(log), extra)
        rows.append(row)
        if "error" in row:
            print(f"| {row['log']} | error: {row['error']} |")
        else:
            print("| " + " | ".join(fmt(row[c]) for c in cols) + " |", flush=True)
    (out / "table.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
