"""``hiper kb info|check|bench``: look after a knowledge base."""

from __future__ import annotations

from typing import Annotated, Any

import typer

from hiper_cli.commands._common import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands._render import console, group, print_json

__all__ = ["kb_app", "register"]

kb_app = group(
    "kb",
    "Inspect, check and benchmark a knowledge base.\n\nExample: hiper kb info --kb scene.hiper",
)



@kb_app.command("info")
def info_command(
    kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None, as_json: bool = JSON_OPTION
) -> None:
    """Counts per layer and class, environments, sessions and size on disk.

    Example: hiper kb info --kb scene.hiper --json
    """
    from hiper_cli.graph import open_kb_for_reading

    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        data = knowledge.info()
    if as_json:
        print_json(data)
        return
    from rich.table import Table

    out = console()
    totals = data["totals"]
    out.print(
        f"[bold]{data['kb']}[/]: {totals['observation']} observations, {totals['instance']} instances, "
        f"{totals['analysis']} analyses, {totals['environment']} environments, "
        f"{data['size_bytes'] / 1e6:.1f} MB on disk"
    )
    table = Table("type", "layer", "class", "count")
    for c in data["counts"]:
        table.add_row(c["type"], c["layer"] or "", c["class"] or "", str(c["count"]))
    out.print(table)
    sessions = Table("session", "log", "frames", "finished")
    for s in data["sessions"]:
        sessions.add_row(str(s["id"]), s["log_path"], str(s["frames"]), "yes" if s["ended_s"] else "no")
    if data["sessions"]:
        out.print(sessions)


@kb_app.command("check")
def check_command(
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    no_repair: Annotated[
        bool, typer.Option("--no-repair", help="Only report; do not rebuild the graph.")
    ] = False,
    as_json: bool = JSON_OPTION,
) -> None:
    """Verify the documents and that the scene graph agrees with them; rebuild the graph if not.

    Exit code 1 when the knowledge base is (still) inconsistent.

    Example: hiper kb check --kb scene.hiper
    """
    from hiper_cli.graph import open_kb

    # open without the automatic catch-up so the check sees what a crash left behind
    with open_kb(kb, docs_dir=kb_docs, sync=False) as knowledge:
        report = knowledge.check(repair=not no_repair)
    data = report.to_dict()
    if as_json:
        print_json(data)
    else:
        out = console()
        for p in report.problems:
            out.print(f"[yellow]problem:[/] {p}")
        if report.repaired:
            out.print("graph rebuilt from the documents")
        out.print("[green]consistent[/]" if report.ok else "[red]inconsistent[/]")
    if not report.ok:
        raise typer.Exit(1)


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
    from hiper_cli.errors import ConfigError
    from hiper_cli.graph.bench import BenchConfig, run_bench

    try:
        counts = [int(s) for s in sizes.split(",") if s.strip()]
    except ValueError as err:
        raise ConfigError(f"--sizes {sizes!r}: expected comma-separated integers, e.g. 10000,100000") from err
    if not counts or min(counts) <= 0:
        raise ConfigError(f"--sizes {sizes!r}: expected positive observation counts")
    config = BenchConfig(obs_per_frame=obs_per_frame, queries=queries, instance_updates=not no_instances,
                         observation_detail=detail, graph_sync_s=graph_sync_s, follower=not inline_graph)
    out = console()

    def show(r: dict[str, Any]) -> None:
        if as_json:
            return
        lat = "  ".join(f"{k} {v['p50_ms']:.2f}/{v['p95_ms']:.2f} ms" for k, v in r["latency"].items())
        follower = (f" + follower {r['follower_peak_rss_mb']:.0f} MB" if r["follower_peak_rss_mb"] else "")
        out.print(
            f"[bold]{r['observations']:>8}[/] obs: documents {r['ingest_obs_per_s']:.0f}/s "
            f"({r['ingest_obs_per_cpu_s']:.0f}/CPU-s), graph {r['graph_sync_obs_per_s']:.0f}/s "
            f"({r['graph']}), end to end {r['end_to_end_obs_per_s']:.0f}/s, peak RSS "
            f"{r['peak_rss_mb']:.0f} MB{follower}, load {r['load_average_1min']}\n    p50/p95: {lat}"
        )

    results = run_bench(counts, config, on_result=show)
    if as_json:
        print_json(results)


def register(app: typer.Typer) -> None:
    app.add_typer(kb_app, name="kb")
