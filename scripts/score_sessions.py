"""Score a knowledge base built from several logs of one place (``scripts/measure_sessions.sh``).

Usage: score_sessions.py EXPORT.json LOG [LOG ...] (the logs in the order they were perceived;
each with the ``gt/instances.json`` of ``hiper sim`` or the realistic worlds).

Static foreground instances (people and ``unknown`` left out) against the logs' observed
objects, matched by class (or alt class) with centres within ``MATCH_M``, nearest first, one to
one. Prints one line per figure:

- duplicates: instances within ``MATCH_M`` of an object of their class that another instance
  took (one object, two instances), against the union of all the logs' objects;
- vacated: instances marked vacated, and how many have no object of their class within
  ``MATCH_M`` in the last log (their place is empty there);
- now: the instances not vacated, and how many lie on an object of the last log (the rest:
  objects only earlier logs saw, stale copies of moved objects, false positives).
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

MATCH_M = 0.5
LEFT_OUT = ("person", "unknown")


def _objects(log: Path) -> list[dict]:
    data = json.loads((log / "gt" / "instances.json").read_text())
    return [dict(centre=np.asarray(e["center"], float), cls=e["class"], alt=e.get("alt_classes") or [])
            for e in data["instances"]
            if e["layer"] == "foreground" and e["class"] not in LEFT_OUT and e.get("observed")]


def _match(instances: list[dict], objects: list[dict]) -> tuple[dict[int, int], set[int]]:
    """(instance -> object) one to one, nearest first; and the instances with any candidate."""
    cand = []
    for i, inst in enumerate(instances):
        centre = np.asarray(inst["box"]["center_m"], float)
        for k, obj in enumerate(objects):
            if inst["class"] == obj["cls"] or inst["class"] in obj["alt"]:
                d = float(np.linalg.norm(centre - obj["centre"]))
                if d <= MATCH_M:
                    cand.append((d, i, k))
    matched: dict[int, int] = {}
    for _, i, k in sorted(cand):
        if i not in matched and k not in matched.values():
            matched[i] = k
    return matched, {i for _, i, _ in cand}


def main(export: Path, logs: list[Path]) -> None:
    data = json.loads(export.read_text())
    insts = [i for i in data["instances"] if i["layer"] == "foreground" and i["class"] not in LEFT_OUT]
    union: list[dict] = []
    for log in logs:  # an object at one place in two logs is one object
        for obj in _objects(log):
            same = [o for o in union
                    if o["cls"] == obj["cls"] and np.linalg.norm(o["centre"] - obj["centre"]) < 0.1]
            if not same:
                union.append(obj)
    matched, near = _match(insts, union)
    dup = Counter(insts[i]["class"] for i in near - set(matched))
    print(f"instances {len(insts)} ({dict(sorted(Counter(i['class'] for i in insts).items()))})")
    print(f"duplicates {sum(dup.values())} {dict(sorted(dup.items()))}")
    last = _objects(logs[-1])
    vacated = [i for i in insts if i.get("vacated_s") is not None]
    empty = sum(not _match([i], last)[0] for i in vacated)
    print(f"vacated {len(vacated)}, of them empty in the last log {empty}")
    live = [i for i in insts if i.get("vacated_s") is None]
    on_last, _ = _match(live, last)
    off = Counter(live[i]["class"] for i in range(len(live)) if i not in on_last)
    print(f"now: {len(live)} instances, {len(on_last)} on an object of the last log, "
          f"{len(live) - len(on_last)} not {dict(sorted(off.items()))}")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: score_sessions.py EXPORT.json LOG [LOG ...]")
    main(Path(sys.argv[1]), [Path(p) for p in sys.argv[2:]])
