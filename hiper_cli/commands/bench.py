"""``hiper bench``: the paper's ablation study and tasks, reproduced offline (``bench.benchmark``)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.render import console, emit, unit_progress
from hiper_cli.render.bench import show_bench

HELP = (
    "The paper's benchmark (section VII): per world a simulated log (mapping, then people), perceived "
    "in the ablation configurations C1-C5 (Tables II and III against the ground truth), then the "
    "fetch-and-carry tasks T1-T4 on the map, 10 runs each; writes OUT/report.md with PNG figures "
    "(needs matplotlib: pip install 'hiper\\[plot]'). --quick: one world, 2 runs, a short log.\n\n"
    "Example: hiper bench --quick -o out/bench"
)
Opt = typer.Option


def bench(
    out: Annotated[Path, Opt("--out", "-o", help="Output folder for the report, figures and logs.")],
    quick: bool = Opt(False, "--quick", help="One world, 2 runs, a 90 s log (CI: a few minutes)."),
    worlds: str | None = Opt(None, "--worlds", help="Comma-separated: house, hospital, office."),
    configs: str | None = Opt(None, "--configs", help="Comma-separated: C1..C5 (default all)."),
    runs: int | None = Opt(None, "--runs", help="Runs per task, configuration and world (10)."),
    seed: int = Opt(0, "--seed", help="Seed of the worlds, logs and runs."),
    log_s: float | None = Opt(None, "--log-s", help="Length of each world's log in seconds (600)."),
    mapping_s: float | None = Opt(None, "--mapping-s", help="Its mapping phase in seconds (60)."),
    time_limit_s: float = Opt(600.0, "--time-limit-s", help="A task fails beyond this (paper: 600)."),
    as_json: Json = False,
) -> None:
    from hiper_cli.bench.benchmark import benchmark

    command = " ".join(["hiper bench", *(shlex.quote(a) for a in sys.argv[2:])])
    with unit_progress("bench", console(), enabled=not as_json) as bar:
        summary = benchmark(out, command, quick=quick, worlds=worlds, configs=configs, runs=runs, seed=seed,
                            log_s=log_s, mapping_s=mapping_s, time_limit_s=time_limit_s,
                            on_start=bar.start if bar else None, progress=bar.step if bar else None)
    emit(summary, as_json, show_bench)


def register(app: HiperTyper) -> None:
    app.command("bench", help=HELP)(bench)
