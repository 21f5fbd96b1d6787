"""``hiper kb bench``: ingest rate, query latencies and memory of fresh knowledge bases."""

from __future__ import annotations

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.cmdline import kb as o
from hiper_cli.render import console, print_json
from hiper_cli.render.kb import show_bench_size

__all__ = ["register"]


@o.kb_app.command("bench")
def bench_command(sizes: o.Sizes = "10000,100000,500000", queries: o.Queries = 200,
                  obs_per_frame: o.ObsPerFrame = 20, no_instances: o.NoInstances = False,
                  detail: o.Detail = "batch", graph_sync_s: o.GraphSyncS = 2.0,
                  inline_graph: o.InlineGraph = False, as_json: Json = False) -> None:
    """Ingest rate, p50/p95 query latencies and peak memory at several sizes (fresh KBs in /tmp).

    Example: hiper kb bench --sizes 10000,100000 --json
    """
    from hiper_cli.graph.bench import BenchConfig, parse_sizes, run_bench

    config = BenchConfig(obs_per_frame=obs_per_frame, queries=queries, instance_updates=not no_instances,
                         observation_detail=detail, graph_sync_s=graph_sync_s, follower=not inline_graph)
    out = console()
    show = None if as_json else lambda r: show_bench_size(out, r)
    results = run_bench(parse_sizes(sizes), config, on_result=show)
    if as_json:
        print_json(results)


def register(app: HiperTyper) -> None:
    """Nothing to do: the command adds itself to ``hiper kb`` on import."""
