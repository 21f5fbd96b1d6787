"""``hiper kb bench``: ingest rate, query latencies and memory of fresh knowledge bases."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import console, print_json
from hiper_cli.commands.kb import kb_app

__all__ = ["register"]


@kb_app.command("bench")
def bench_command(
    sizes: Annotated[
        str, typer.Option("--sizes", help="Comma-separated observation counts.")
    ] = "10000,100000,500000",
    queries: Annotated[int, typer.Option("--queries", help="Queries per latency figure.")] = 200,
    obs_per_frame: Annotated[int, typer.Option("--obs-per-frame", help="Observations per frame.")] = 20,
    no_instances: Annotated[
        bool, typer.Option("--no-instances", help="Observations only (no instance upsert per observation).")
    ] = False,
    detail: Annotated[
        str, typer.Option("--detail", help="Observations in the graph: batch, summary or full.")
    ] = "batch",
    graph_sync_s: Annotated[
        float,
        typer.Option("--graph-sync-s", help="Graph sync interval during ingest (2 s); with --inline-graph "
                     "0 = once after the ingest (shows the document side's memory alone)."),
    ] = 2.0,
    inline_graph: Annotated[
        bool, typer.Option("--inline-graph", help="Sync the graph in the writer process, as perceive "
                           "does, instead of a graph follower process beside it.")
    ] = False,
    as_json: bool = JSON_OPTION,
) -> None:
    """Ingest rate, p50/p95 query latencies and peak memory at several sizes (fresh KBs in /tmp).

    Example: hiper kb bench --sizes 10000,100000 --json
    """
    from hiper_cli.commands._tables import show_bench_size
    from hiper_cli.graph.bench import BenchConfig, parse_sizes, run_bench

    counts = parse_sizes(sizes)
    config = BenchConfig(obs_per_frame=obs_per_frame, queries=queries, instance_updates=not no_instances,
                         observation_detail=detail, graph_sync_s=graph_sync_s, follower=not inline_graph)
    out = console()
    results = run_bench(counts, config, on_result=None if as_json else lambda r: show_bench_size(out, r))
    if as_json:
        print_json(results)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper kb`` on import."""
