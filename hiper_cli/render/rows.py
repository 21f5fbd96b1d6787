"""Print what the library made for people (``TextTable``s, lines, raw text) or ``--json``."""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import Any

from hiper_cli.render.text import console, print_json, safe_text

__all__ = ["emit_view", "print_lines", "print_table"]

_COMPACT = {"box": None, "pad_edge": False, "padding": (0, 1, 0, 0), "header_style": "bold underline"}


def emit_view(data: Any, view: Any, as_json: bool) -> None:
    """``data`` as JSON (``--json``), else ``view``: a ``TextTable``, a list of them or of lines,
    or raw text (a Turtle graph: written as it is, without rich)."""
    if as_json:
        print_json(data)
    elif isinstance(view, str):
        text = safe_text(view, markup=False)
        sys.stdout.write(text if not text or text.endswith("\n") else text + "\n")
    elif isinstance(view, list):
        for item in view:
            print_table(item) if hasattr(item, "headers") else print_lines([item])
    else:
        print_table(view)


def print_table(table: Any, out: Any = None) -> None:
    """The headline in bold, then the rows (every string escaped: they come from the KB)."""
    from rich.table import Table

    out = out or console()
    if table.headline:
        out.print(f"[bold]{safe_text(table.headline)}[/]")
    if not table.headers:
        return
    rich_table = Table(**(_COMPACT if table.compact else {}))  # type: ignore[arg-type]
    for name in table.headers:
        rich_table.add_column(safe_text(name), no_wrap=table.compact and name not in table.wrap)
    for row in table.rows:
        rich_table.add_row(*(safe_text(v) for v in row))
    out.print(rich_table)


def print_lines(lines: Iterable[str], out: Any = None) -> None:
    out = out or console()
    for line in lines:
        out.print(safe_text(line))
