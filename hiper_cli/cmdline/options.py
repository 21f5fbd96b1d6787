"""The options several commands share, each written once: knowledge base, ``--json``, log argument."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli import DEFAULT_KB

__all__ = ["DEFAULT_KB", "JSON_OPTION", "LOG_ARGUMENT", "KbDocsOption", "KbOption"]

KB_HELP = "Knowledge base: a directory, or the http:// URL of a SPARQL endpoint holding the scene graph."
KB_DOCS_HELP = f"Documents directory when --kb is an http:// endpoint (default ./{DEFAULT_KB})."
KbOption = Annotated[str, typer.Option("--kb", help=KB_HELP)]
KbDocsOption = Annotated[Path | None, typer.Option("--kb-docs", help=KB_DOCS_HELP)]
JSON_OPTION = typer.Option(False, "--json", help="Print machine-readable JSON on stdout.")

LOG_ARGUMENT = typer.Argument(..., help="TUM RGB-D folder, rosbag1 .bag, rosbag2 folder or .mcap file.")
