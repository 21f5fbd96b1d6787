"""``hiper export`` and ``hiper import``: the knowledge base in exchange formats."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands._render import console, print_json, safe_text

__all__ = ["register"]

FormatOption = Annotated[
    str | None,
    typer.Option("--format", "-f", help="turtle, nquads, jsonld, graphml or json (default: by suffix)."),
]


def export_command(
    out: Annotated[Path, typer.Argument(help="Output file (.ttl, .nq, .jsonld, .graphml, .json).")],
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    fmt: FormatOption = None,
    observations: Annotated[
        bool, typer.Option("--observations", help="Include every observation: its document (JSON), "
                           "its node and provenance link (RDF, GraphML; the scene graph holds batches).")
    ] = False,
    as_json: bool = JSON_OPTION,
) -> None:
    """Export the knowledge base as Turtle, N-Quads, JSON-LD, GraphML or the documented JSON.

    Example: hiper export scene.json --kb scene.hiper --format json
    """
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.graph.exchange import export_kb, guess_format

    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        summary = export_kb(knowledge, out, fmt or guess_format(out), observations=observations)
    if as_json:
        print_json(summary)
    else:
        console().print(f"wrote {safe_text(summary['path'])} ({safe_text(summary['format'])})")


def import_command(
    path: Annotated[Path, typer.Argument(help="A file written by 'hiper export'.")],
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    fmt: FormatOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Import an export (any of the five formats) into a knowledge base.

    Example: hiper import scene.json --kb copy.hiper
    """
    from hiper_cli.graph import open_kb
    from hiper_cli.graph.exchange import import_kb

    with open_kb(kb, docs_dir=kb_docs) as knowledge:
        summary = import_kb(knowledge, path, fmt)
    if as_json:
        print_json(summary)
    else:
        counts = ", ".join(f"{n} {_plural(k, n)}" for k, n in summary["counts"].items())
        console().print(f"imported {counts} into {safe_text(summary['kb'])}")


def _plural(kind: str, n: int) -> str:
    """"1 environment", "13 instances", "2 analyses"."""
    if n == 1:
        return kind
    return kind[:-2] + "es" if kind.endswith("is") else kind + "s"


def register(app: typer.Typer) -> None:
    app.command("export")(export_command)
    app.command("import")(import_command)
