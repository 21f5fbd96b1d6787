"""What ``hiper bench`` shows: per world, each configuration's task times, and the report."""

from __future__ import annotations

from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_bench"]


def show_bench(out: Any, summary: dict[str, Any]) -> None:
    """One table per world (median seconds and successes of T1-T4 per configuration)."""
    from rich.table import Table

    for world, cells in summary["tasks"].items():
        table = Table("config", *[f"{t} median s (ok)" for t in ("T1", "T2", "T3", "T4")],
                      title=safe_text(world))
        for name, row in cells.items():
            table.add_row(safe_text(name), *[
                f"{'-' if c['median_time_s'] is None else format(c['median_time_s'], '.1f')} "
                f"({c['successes']}/{c['runs']})" for c in row.values()])
        out.print(table)
    out.print(f"[green]wrote[/] {safe_text(summary['report'])}")
