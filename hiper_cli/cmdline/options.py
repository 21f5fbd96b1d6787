"""The options several commands share, each written once: knowledge base, ``--json``, log argument."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli import DEFAULT_KB

__all__ = ["DEFAULT_KB", "JSON_OPTION", "LOG_ARGUMENT", "Json", "Kb", "KbDocs", "KbDocsOption", "KbOption",
           "Log"]

KB_HELP = "Knowledge base: a directory, or the http:// URL of a SPARQL endpoint holding the scene graph."
KB_DOCS_HELP = f"Documents directory when --kb is an http:// endpoint (default ./{DEFAULT_KB})."
KbOption = Annotated[str, typer.Option("--kb", help=KB_HELP)]
KbDocsOption = Annotated[Path | None, typer.Option("--kb-docs", help=KB_DOCS_HELP)]
JSON_HELP = "Print machine-readable JSON on stdout."
JSON_OPTION = typer.Option(False, "--json", help=JSON_HELP)
# short names for signatures: ``kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, as_json: Json = False``
Kb = KbOption
KbDocs = KbDocsOption
Json = Annotated[bool, typer.Option("--json", help=JSON_HELP)]

LOG_HELP = "TUM RGB-D folder, rosbag1 .bag, rosbag2 folder or .mcap file."
LOG_ARGUMENT = typer.Argument(..., help=LOG_HELP)
Log = Annotated[Path, typer.Argument(help=LOG_HELP)]
