"""What ``hiper tools`` shows: the agent tools, their inputs and descriptions."""

from __future__ import annotations

from typing import Any

__all__ = ["show_tools"]


def show_tools(out: Any, fmt: str) -> None:
    """One row per tool of ``hiper_cli.agent.TOOLS``; the schemas themselves are in ``--json``."""
    from rich.table import Table

    from hiper_cli.agent import TOOLS

    title = f"{len(TOOLS)} tools ({fmt}; --json for the schemas)"
    table = Table("tool", "inputs", "description", title=title)
    for t in TOOLS:
        table.add_row(t.name, ", ".join(t.input_schema["properties"]), t.description)
    out.print(table)
