"""The options of ``hiper kb``."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.cmdline.app import group

__all__ = ["Detail", "GraphSyncS", "InlineGraph", "KeepObservations", "NoInstances", "NoRepair",
           "ObsPerFrame", "Queries", "Sizes", "kb_app"]

kb_app = group("kb", "Inspect, check and benchmark a knowledge base.\n\n"
               "Example: hiper kb info --kb scene.hiper")
NoRepair = Annotated[bool, typer.Option("--no-repair", help="Only report; do not rebuild the graph.")]
KeepObservations = Annotated[str, typer.Option(
    "--keep-observations", help="Keep raw observations this long before the newest stamp "
    "('10 minutes', '2 h'; default 0: summarise all that add nothing).")]

# hiper kb bench
Sizes = Annotated[str, typer.Option("--sizes", help="Comma-separated observation counts.")]
Queries = Annotated[int, typer.Option("--queries", help="Queries per latency figure.")]
ObsPerFrame = Annotated[int, typer.Option("--obs-per-frame", help="Observations per frame.")]
NoInstances = Annotated[bool, typer.Option(
    "--no-instances", help="Observations only (no instance upsert per observation).")]
Detail = Annotated[str, typer.Option("--detail", help="Observations in the graph: batch, summary or full.")]
GraphSyncS = Annotated[float, typer.Option(
    "--graph-sync-s", help="Graph sync interval during ingest (2 s); with --inline-graph "
    "0 = once after the ingest (shows the document side's memory alone).")]
InlineGraph = Annotated[bool, typer.Option(
    "--inline-graph", help="Sync the graph in the writer process, as perceive "
    "does, instead of a graph follower process beside it.")]
