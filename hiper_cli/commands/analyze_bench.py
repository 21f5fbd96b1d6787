"""``hiper analyze bench``: features and a heatmap timed on two hours of data."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import JSON_OPTION
from hiper_cli.commands.analyze import analyze_app

__all__ = ["register"]


@analyze_app.command("bench")
def bench_command(
    kb: Annotated[Path, typer.Option("--kb", help="Bench knowledge base (filled on first use).")] = Path(
        "/tmp/hiper-analyze-bench.hiper"),
    hours: Annotated[float, typer.Option("--hours", help="Hours of data when filling it.")] = 2.0,
    as_json: bool = JSON_OPTION,
) -> None:
    """Time features (all classes) and a heatmap on a KB of 2 h of data (>= 1 M observations,
    >= 200 k trajectory rows), each in a fresh process with its peak memory.

    Example: hiper analyze bench --kb /tmp/bench.hiper --json
    """
    from hiper_cli.analyze.bench import run_analyze_bench
    from hiper_cli.analyze.views import bench_lines
    from hiper_cli.render.rows import emit_view

    data = run_analyze_bench(kb, hours=hours)
    emit_view(data, bench_lines(data, str(kb)), as_json)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper analyze`` on import."""
