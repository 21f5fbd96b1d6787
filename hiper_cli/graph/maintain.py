"""Looking after a knowledge base by its location: what it holds, whether it is consistent,
its sessions, compaction. Each returns the dict ``hiper kb ... --json`` prints, so the command
line and Python users call the same functions."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hiper_cli.graph.kb import open_kb, open_kb_for_reading

__all__ = ["check_kb", "compact_kb", "export_to", "import_from", "kb_info", "kb_sessions"]


def kb_info(location: str | Path, docs_dir: str | Path | None = None) -> dict[str, Any]:
    """Totals, counts per type, layer and class, sessions and size on disk."""
    with open_kb_for_reading(location, docs_dir=docs_dir) as knowledge:
        return knowledge.info()


def check_kb(location: str | Path, docs_dir: str | Path | None = None, *,
             repair: bool = True) -> dict[str, Any]:
    """The documents verified and the graph compared with them; rebuilt when not (``repair``).

    Opened without the automatic catch-up so the check sees what a crash left behind; a graph
    that cannot be opened is rebuilt from the documents (with ``repair``)."""
    with open_kb(location, docs_dir=docs_dir, sync=False, create=False, read_only=not repair,
                 rebuild_damaged_graph=repair) as knowledge:
        return knowledge.check(repair=repair).to_dict()


def kb_sessions(location: str | Path, docs_dir: str | Path | None = None) -> dict[str, Any]:
    """The sessions: id, place, log, log stamps, when each ran, alignment."""
    with open_kb_for_reading(location, docs_dir=docs_dir) as knowledge:
        return {"kb": str(location), "sessions": knowledge.session_records()}


def compact_kb(location: str | Path, keep_raw_s: float | None = 0.0) -> dict[str, Any]:
    """Observations that add nothing summarised (those of the last ``keep_raw_s`` kept raw)."""
    from hiper_cli.graph.compact import compact

    with open_kb(location, create=False) as knowledge:
        return compact(knowledge, keep_raw_s=keep_raw_s or 0.0).to_dict()


def export_to(location: str | Path, out: Path, fmt: str | None = None, *, docs_dir: str | Path | None = None,
              observations: bool = False) -> dict[str, Any]:
    """The knowledge base written to ``out`` in ``fmt`` (default: by suffix; ``exchange``)."""
    from hiper_cli.graph.exchange import export_kb, guess_format

    with open_kb_for_reading(location, docs_dir=docs_dir) as knowledge:
        return export_kb(knowledge, out, fmt or guess_format(out), observations=observations)


def import_from(location: str | Path, path: Path, fmt: str | None = None, *,
                docs_dir: str | Path | None = None) -> dict[str, Any]:
    """An export (any format ``exchange`` writes) read into the knowledge base at ``location``."""
    from hiper_cli.graph.exchange import import_kb

    with open_kb(location, docs_dir=docs_dir) as knowledge:
        return import_kb(knowledge, path, fmt)
