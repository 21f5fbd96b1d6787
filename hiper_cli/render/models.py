"""What ``hiper models`` shows: the known detectors, a fetched model, an added one."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_added", "show_fetched", "show_models"]


def show_models(out: Any, data: dict[str, Any]) -> None:
    """``hiper models list``: one row per model, and the models folder."""
    from rich.table import Table

    table = Table("name", "layout", "px", "MB", "licence", "mAP", "sha256", "where")
    home = str(Path.home())
    for r in data["models"]:
        size = f"{r['size_bytes'] / 1e6:.1f}" if r["size_bytes"] else "?"
        sha = f"{r['sha256']}"[:8] if r["sha256"] else "unknown"
        coco = f"{r['coco_map']:.1f}" if r["coco_map"] is not None else "?"
        where = (
            str(r["path"]).replace(home, "~", 1) if r["path"] else ("-> fetch" if r["url"] else "-> export")
        )
        table.add_row(str(r["name"]), str(r["layout"]), f"{r['input_px'] or '?'}", size,
                      safe_text(str(r["licence"])), coco, sha, safe_text(where))
    out.print(table)
    out.print(
        f"models folder: {safe_text(data['models_dir'])}; sha256 'unknown': not verified by "
        "hiper, fetched only with --trust-unverified"
    )


def show_fetched(out: Any, data: dict[str, Any]) -> None:
    """``hiper models fetch``: where the model is, what was downloaded, whether it was verified."""
    check = "verified" if data["verified"] else "NOT verified: no known sha256, check it yourself"
    resumed = f", resumed at {data['resumed_from']} bytes" if data["resumed_from"] else ""
    got = (f"{data['downloaded_bytes']} bytes downloaded{resumed}" if data["downloaded_bytes"]
           else "already here")
    out.print(f"{data['name']} -> {safe_text(data['path'])} ({got}; sha256 {data['sha256']} {check})")


def show_added(out: Any, data: dict[str, Any]) -> None:
    """``hiper models add``: where the model went, its layout and classes, how to use it."""
    out.print(f"{data['name']} -> {safe_text(data['path'])} ({data['layout']} layout, "
              f"{data['classes']} classes; use --detector {data['name']})")
