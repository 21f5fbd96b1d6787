"""Sessions as first-class records: which log, when, and the transform that aligned it.

A knowledge base is one place over many sessions (one ``perceive`` run each). The documents'
``sessions`` table holds the log, the wall-clock start and end and the progress; this module
adds what a session of a lasting memory needs besides: the rigid transform ``T_map_log`` that
carried the log's poses into the place's map frame (identity for the first session, or when
the log shares the map frame), how well it fitted, and the span of log stamps it covered.
The transform lives in the documents' ``meta`` table (key ``session_align:ID``), so no schema
change is needed; the scene graph carries it on the session node (``hiper:alignmentJson``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiper_cli.graph.documents import DocumentStore, Session

__all__ = ["Alignment", "alignment_of", "record_alignment", "session_record", "stamp_span"]

_KEY = "session_align:{}"


@dataclass(frozen=True)
class Alignment:
    """How a session's log frame was carried into the map frame.

    ``method``: ``identity`` (first session of a place, or ``--align none``), ``file`` (given by
    the user), ``registration`` (found from the static background). ``fitness``: share of the
    log's background points within the ICP distance of the map (1.0 for identity or a file);
    ``rmse_m``: their mean distance; ``note``: how a registration was refined (or why not)."""

    T_map_log: np.ndarray
    method: str
    fitness: float = 1.0
    rmse_m: float = 0.0
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        out = {"T_map_log": np.asarray(self.T_map_log, dtype=float).round(6).tolist(), "method": self.method,
               "fitness": round(float(self.fitness), 4), "rmse_m": round(float(self.rmse_m), 4)}
        return out | ({"note": self.note} if self.note else {})

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Alignment:
        return cls(np.asarray(d["T_map_log"], dtype=np.float64), str(d["method"]),
                   float(d.get("fitness", 1.0)), float(d.get("rmse_m", 0.0)), str(d.get("note", "")))

    @classmethod
    def identity(cls) -> Alignment:
        return cls(np.eye(4), "identity")


def record_alignment(docs: DocumentStore, session_id: int, alignment: Alignment) -> None:
    """Store ``alignment`` for the session (inside a transaction); the session's change
    sequence moves on, so the graph's next catch-up rewrites its node."""
    docs.set_meta(_KEY.format(session_id), json.dumps(alignment.to_dict()))
    docs._db.execute("UPDATE sessions SET seq = ? WHERE id = ?", (docs._current_seq(), session_id))


def alignment_of(docs: DocumentStore, session_id: int) -> Alignment | None:
    text = docs.meta(_KEY.format(session_id))
    return None if text is None else Alignment.from_dict(json.loads(text))


def stamp_span(docs: DocumentStore, session_id: int) -> tuple[float | None, float | None]:
    """The first and last log stamp (s) of the frames the session committed."""
    row = docs._db.execute(
        "SELECT MIN(stamp_s), MAX(stamp_s) FROM poses WHERE session_id = ?", (session_id,)
    ).fetchone()
    if row is None or row[0] is None:
        return None, None
    return float(row[0]), float(row[1])


def session_record(docs: DocumentStore, session: Session, env_names: dict[str, str]) -> dict[str, Any]:
    """The session as ``hiper kb sessions --json`` lists it (and the graph node carries)."""
    first_s, last_s = stamp_span(docs, session.id)
    align = alignment_of(docs, session.id)
    return {
        **session.to_dict(),
        "environment": env_names.get(session.env_uuid, session.env_uuid),
        "first_stamp_s": first_s,
        "last_stamp_s": last_s,
        "alignment": None if align is None else align.to_dict(),
    }
