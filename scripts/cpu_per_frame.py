"""CPU milliseconds per frame of the whole ``hiper perceive`` command, median of several runs.

Usage: python scripts/cpu_per_frame.py OUTDIR LOG [LOG ...] [--runs N] [--code DIR] [-- perceive options]

Runs ``hiper perceive LOG --kb OUTDIR/NAME.hiper`` ``--runs`` times (default 3) per log, each into a
new knowledge base (a log perceived again into a place the knowledge base holds is first registered
to its map: seconds of work that are not the per-frame cost),
with the checkout at ``--code`` (default this one) on ``PYTHONPATH``, and prints per log the median
(and range) of the command's CPU time per frame (user + system, all its threads: what the command
costs a machine, far less sensitive to other load than wall time) and of its frames per second
(wall clock: noisy on a shared machine). 30 frames/s on half a core is 1000 × 0.5 / 30 ≈ 17 ms.
No farm, no scorer: one process at a time on this machine.
"""

from __future__ import annotations

import os
import resource
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = next((p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared") if p.is_dir()),
              ROOT.parent / "shared")


def frames(log: Path) -> int:
    lines = (log / "rgb.txt").read_text().splitlines()
    return sum(1 for line in lines if line.strip() and not line.startswith("#"))


def one_run(code: Path, log: Path, kb: Path, extra: list[str]) -> tuple[float, float]:
    """CPU seconds (user + system of the child and its threads) and wall seconds of one perceive."""
    # -P: the checkout at ``code``, not the one in the current folder (``-m`` puts that first)
    env = dict(os.environ, PYTHONPATH=str(code))
    env.setdefault("HIPER_MODELS", str(SHARED / "models"))
    shutil.rmtree(kb, ignore_errors=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    run = subprocess.run([sys.executable, "-P", "-m", "hiper_cli", "perceive", str(log), "--kb", str(kb),
                          "--json", *extra],
                         capture_output=True, text=True, env=env, check=False)
    wall_s = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode:
        tail = (run.stdout + run.stderr).strip().splitlines()[-1:]
        raise SystemExit(f"{log}: perceive failed: {tail}")
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, wall_s


def main(argv: list[str]) -> None:
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    args = argv[: argv.index("--")] if "--" in argv else argv
    runs, code = 3, ROOT
    if "--runs" in args:
        i = args.index("--runs")
        runs = int(args[i + 1])
        del args[i : i + 2]
    if "--code" in args:
        i = args.index("--code")
        code = Path(args[i + 1]).resolve()
        del args[i : i + 2]
    if len(args) < 2:
        raise SystemExit(__doc__)
    out = Path(args[0])
    out.mkdir(parents=True, exist_ok=True)
    print(f"{'log':<28} {'frames':>6} {'cpu_ms/frame (median, range)':>30} {'frames/s (median)':>18}")
    for log in map(Path, args[1:]):
        n = frames(log)
        cpu_ms, fps = [], []
        for _ in range(runs):
            cpu_s, wall_s = one_run(code, log, out / f"{log.name}.hiper", extra)
            cpu_ms.append(1000.0 * cpu_s / n)
            fps.append(n / wall_s)
        spread = f"{statistics.median(cpu_ms):.1f} ({min(cpu_ms):.1f}-{max(cpu_ms):.1f})"
        print(f"{log.name:<28} {n:>6} {spread:>30} {statistics.median(fps):>18.1f}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
