"""``hiper export`` and ``hiper import``: the knowledge base in exchange formats (``graph.maintain``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Json, Kb, KbDocs
from hiper_cli.render import emit
from hiper_cli.render.kb import show_export, show_import

__all__ = ["register"]

Format = Annotated[str | None, typer.Option(
    "--format", "-f", help="turtle, nquads, jsonld, graphml or json (default: by suffix).")]
Out = Annotated[Path, typer.Argument(help="Output file (.ttl, .nq, .jsonld, .graphml, .json).")]
Observations = Annotated[bool, typer.Option("--observations", help=(
    "Include every observation: its document (JSON), its node and provenance link (RDF, GraphML; the "
    "scene graph holds batches)."))]
Export = Annotated[Path, typer.Argument(help="A file written by 'hiper export'.")]


def export_command(out: Out, kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, fmt: Format = None,
                   observations: Observations = False, as_json: Json = False) -> None:
    """Export the knowledge base as Turtle, N-Quads, JSON-LD, GraphML or the documented JSON.

    Example: hiper export scene.json --kb scene.hiper --format json
    """
    from hiper_cli.graph.maintain import export_to
    emit(export_to(kb, out, fmt, docs_dir=kb_docs, observations=observations), as_json, show_export)


def import_command(path: Export, kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, fmt: Format = None,
                   as_json: Json = False) -> None:
    """Import an export (any of the five formats) into a knowledge base.

    Example: hiper import scene.json --kb copy.hiper
    """
    from hiper_cli.graph.maintain import import_from
    emit(import_from(kb, path, fmt, docs_dir=kb_docs), as_json, show_import)


def register(app: HiperTyper) -> None:
    app.command("export")(export_command)
    app.command("import")(import_command)
