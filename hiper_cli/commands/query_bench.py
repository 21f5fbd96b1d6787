"""``hiper query bench``: every query form timed at scale (library: ``query/bench.py``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import JSON_OPTION
from hiper_cli.commands.query import query_app

__all__ = ["register"]


@query_app.command("bench")
def bench_command(
    instances: Annotated[int, typer.Option("--instances", help="Synthetic instances.")] = 10_000,
    observations: Annotated[int, typer.Option("--observations", help="Synthetic observations.")] = 1_000_000,
    queries: Annotated[int, typer.Option("--queries", help="Runs per query form.")] = 50,
    kb: Annotated[Path | None, typer.Option("--kb", help="Keep (or reuse) the synthetic KB here.")] = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Time every query form (p50/p95 ms) on a synthetic knowledge base at scale.

    Example: hiper query bench --instances 10000 --observations 1000000 --kb /tmp/qbench.hiper
    """
    from hiper_cli.query.bench import QueryBenchConfig, run_query_bench
    from hiper_cli.query.views import bench_view
    from hiper_cli.render.rows import emit_view

    config = QueryBenchConfig(instances=instances, observations=observations, queries=queries)
    report = run_query_bench(config, kb_path=kb)
    emit_view(report, bench_view(report), as_json)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper query`` on import."""
