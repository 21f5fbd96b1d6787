"""``hiper bench``: the paper's ablation study and tasks, reproduced offline (``hiper_cli.bench``)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import HiperTyper, console, print_json, safe_text

HELP = (
    "The paper's benchmark (section VII): per world a simulated log (mapping, then people), perceived "
    "in the ablation configurations C1-C5 (Tables II and III against the ground truth), then the "
    "fetch-and-carry tasks T1-T4 on the map, 10 runs each; writes OUT/report.md with PNG figures "
    "(needs matplotlib: pip install 'hiper\\[plot]'). --quick: one world, 2 runs, a short log.\n\n"
    "Example: hiper bench --quick -o out/bench"
)
QUICK_WORLDS, QUICK_RUNS, QUICK_LOG_S, QUICK_MAPPING_S = "house", 2, 90.0, 30.0


def bench(
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder for the report, figures and logs.")],
    quick: bool = typer.Option(False, "--quick", help="One world, 2 runs, a 90 s log (CI: a few minutes)."),
    worlds: str | None = typer.Option(None, "--worlds", help="Comma-separated: house, hospital, office."),
    configs: str | None = typer.Option(None, "--configs", help="Comma-separated: C1..C5 (default all)."),
    runs: int | None = typer.Option(None, "--runs", help="Runs per task, configuration and world (10)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the worlds, logs and runs."),
    log_s: float | None = typer.Option(None, "--log-s", help="Length of each world's log in seconds (600)."),
    mapping_s: float | None = typer.Option(None, "--mapping-s", help="Its mapping phase in seconds (60)."),
    time_limit_s: float = typer.Option(
        600.0, "--time-limit-s", help="A task fails beyond this (paper: 600)."),
    as_json: bool = JSON_OPTION,
) -> None:
    from hiper_cli.bench import (
        BenchSettings,
        parse_configs,
        require_matplotlib,
        run_bench,
        summarize,
        write_report,
    )
    from hiper_cli.bench.tasks import TaskConfig

    require_matplotlib()
    world_text = worlds or (QUICK_WORLDS if quick else "house,hospital,office")
    settings = BenchSettings(
        worlds=tuple(w.strip() for w in world_text.split(",") if w.strip()),
        configs=parse_configs(configs), runs=runs or (QUICK_RUNS if quick else 10), seed=seed,
        log_s=log_s or (QUICK_LOG_S if quick else 600.0),
        mapping_s=mapping_s or (QUICK_MAPPING_S if quick else 60.0),
        tasks=TaskConfig(time_limit_s=time_limit_s),
    )
    screen = console()
    command = " ".join(["hiper bench", *(shlex.quote(a) for a in sys.argv[2:])])
    if as_json:
        result = run_bench(settings, out)
    else:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        with Progress(TextColumn("[bold]bench"), BarColumn(), MofNCompleteColumn(),
                      TextColumn("{task.description}"), TimeElapsedColumn(), console=screen) as bar:
            task = bar.add_task("", total=settings.units())
            result = run_bench(settings, out, lambda what, n: bar.update(task, advance=n, description=what))
    summary = summarize(result)
    report = write_report(result, summary, out, command)
    summary["report"] = str(report)
    if as_json:
        print_json(summary)
        return
    from rich.table import Table

    for world, cells in summary["tasks"].items():
        table = Table("config", *[f"{t} median s (ok)" for t in ("T1", "T2", "T3", "T4")],
                      title=safe_text(world))
        for name, row in cells.items():
            table.add_row(safe_text(name), *[
                f"{'-' if c['median_time_s'] is None else format(c['median_time_s'], '.1f')} "
                f"({c['successes']}/{c['runs']})" for c in row.values()])
        screen.print(table)
    screen.print(f"[green]wrote[/] {safe_text(report)}")


def register(app: HiperTyper) -> None:
    app.command("bench", help=HELP)(bench)
