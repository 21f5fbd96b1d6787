"""The knowledge base's door: named, typed reads and writes for every package above ``graph``.

Only ``graph/`` touches SQLite, Oxigraph or the store's files; the interpretation, the viewer,
re-anchoring and the live runner ask ``KnowledgeBase`` through these methods (with those of
``reads.py`` and ``kb.py``), so a change of storage stays inside this package. docs/kb.md
shows each in use; tests/graph/test_kb_door.py runs those examples and fails on a store reached
around the door.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph.columns import (
    InstanceColumns,
    TrajectoryColumns,
    foreground_classes,
    instance_columns,
    newest_stamp_s,
    trajectory_columns,
)
from hiper_cli.graph.documents import DocumentStore
from hiper_cli.graph.history import Change
from hiper_cli.graph.poserows import matrices
from hiper_cli.model import Environment, Instance, Observation

__all__ = ["DOCUMENTS_FILE", "KbDoor", "KbSizes", "SessionPoses", "is_knowledge_base"]

DOCUMENTS_FILE = "documents.sqlite"


def is_knowledge_base(path: str | Path) -> bool:
    """Whether ``path`` is a knowledge-base folder (it holds a document store)."""
    return (Path(path) / DOCUMENTS_FILE).is_file()


@dataclass(frozen=True)
class SessionPoses:
    """The camera poses a session recorded: ``stamps_s`` (N,), ``T_map_cam`` (N, 4, 4)."""

    session_id: int
    log_path: str
    stamps_s: NDArray[np.float64]
    T_map_cam: NDArray[np.float64]


@dataclass(frozen=True)
class KbSizes:
    """Documents per type and the foreground trajectory rows, for a benchmark's report."""

    documents: dict[str, int]
    trajectory_rows: int


def _aabb(box: Any) -> tuple[list[float], list[float]]:
    lo, hi = box.aabb()
    return [float(v) for v in lo], [float(v) for v in hi]


class KbDoor:
    """Typed reads and writes over ``self.docs`` and ``self.graph`` (mixed into ``KnowledgeBase``)."""

    docs: DocumentStore
    graph: Any
    kb_id: str

    # -- instances in a window, and their trajectories as columns -----------------------------

    def instances_seen(self, t_start_s: float | None = None, t_end_s: float | None = None, *,
                       layer: str | None = None, class_name: str | None = None) -> list[Instance]:
        """The instances seen at some time in [t_start_s, t_end_s] (s; None leaves that end open):
        first sighting at or before its end, last sighting at or after its start; stamp order."""
        found = self.docs.find(type="instance", layer=layer, class_name=class_name, t_start_s=t_start_s)
        return [Instance.from_dict(d) for d in found
                if t_end_s is None or float(d["first_seen_s"]) <= t_end_s]

    def instance_columns(self, class_name: str | None = None, t_start_s: float | None = None,
                         t_end_s: float | None = None, *, layer: str = "foreground") -> InstanceColumns:
        """The boxes of the ``layer`` instances seen in the window (of ``class_name`` or all)."""
        return instance_columns(self.docs, class_name, t_start_s, t_end_s, layer=layer)

    def trajectory_columns(self, class_name: str | None = None, t_start_s: float | None = None,
                           t_end_s: float | None = None) -> TrajectoryColumns:
        """The trajectory rows in the window of the foreground instances (of ``class_name``)."""
        return trajectory_columns(self.docs, class_name, t_start_s, t_end_s)

    def newest_sighting_s(self) -> float | None:
        """The last sighting of the newest foreground instance (None: there is none)."""
        return newest_stamp_s(self.docs)

    def foreground_classes(self) -> list[str]:
        """The classes of the foreground instances, sorted."""
        return foreground_classes(self.docs)

    def instance_summary(self) -> tuple[int, float | None]:
        """How many instances, and the newest sighting among them: what a map built from the
        knowledge base depends on (both read from indexes)."""
        n, newest = self.docs.connection.execute(
            "SELECT COUNT(*), MAX(stamp_s) FROM docs WHERE type = 'instance'").fetchone()
        return int(n), None if newest is None else float(newest)

    # -- observations and poses ---------------------------------------------------------------

    def observations_between(self, t_start_s: float, t_end_s: float) -> list[Observation]:
        """Every observation stamped in [t_start_s, t_end_s] (s), in stamp order."""
        return [Observation.from_dict(d)
                for d in self.docs.find(type="observation", t_start_s=t_start_s, t_end_s=t_end_s)]

    def session_poses(self, session_id: int) -> SessionPoses:
        """The poses ``session_id`` recorded, in pose order."""
        session = self.docs.session(session_id)
        log_path = "" if session is None else session.log_path
        rows = self.docs.connection.execute(
            "SELECT stamp_s, T_map_cam FROM poses WHERE session_id = ? ORDER BY pose_id", (session_id,)
        ).fetchall()
        stamps = [float(r[0]) for r in rows]
        return SessionPoses(session_id, log_path, np.array(stamps, dtype=np.float64),
                            matrices(stamps, [r[1] for r in rows]).reshape(-1, 4, 4))

    def sizes(self) -> KbSizes:
        """Documents per type and the foreground trajectory rows."""
        counts: dict[str, int] = {}
        for kind, _layer, _cls, n in self.docs.counts():
            counts[kind] = counts.get(kind, 0) + n
        db = self.docs.connection
        apart, inline = db.execute(
            "SELECT SUM(json_extract(body, '$.data.trajectory_rows')), "
            "SUM(json_array_length(json_extract(body, '$.data.trajectory'))) FROM docs "
            "WHERE type = 'instance' AND layer = 'foreground'").fetchone()
        return KbSizes(counts, int(apart or 0) + int(inline or 0))

    def change_events(self, session_id: int | None = None) -> list[Change]:
        """The change events (moved | removed | added) found when a session was aligned to the
        place's memory, of every session or of ``session_id``, in stamp order."""
        return [Change(str(d["kind"]), str(d["class"]), str(d["instance_uuid"]), int(d["session"]),
                       float(d["stamp_s"]), d.get("from_m"), d.get("to_m"), str(d["uuid"]))
                for d in self.docs.find(type="change")
                if session_id is None or int(d["session"]) == session_id]

    # -- writes -------------------------------------------------------------------------------

    def store_environment(self, env: Environment) -> None:
        """Write ``env`` (its map, its name) in one transaction."""
        with self.docs.transaction():
            self.docs.put(env.to_dict(), env_uuid=env.uuid)

    def put_batch(self, observations: Sequence[dict[str, Any]], instances: Sequence[Instance],
                  env_uuid: str | None = None) -> None:
        """Observation documents (without a map box) and instances (indexed by their map box)
        in one transaction: a bulk load, e.g. a benchmark's synthetic data."""
        with self.docs.transaction():
            self.docs.put_many([(o, None) for o in observations], env_uuid=env_uuid)
            self.docs.put_many([(i.to_dict(), _aabb(i.box)) for i in instances], env_uuid=env_uuid)

    def write_reanchored(self, observations: Sequence[tuple[Observation, NDArray[np.float64]]],
                         instances: Sequence[Instance], deleted: Sequence[str]) -> None:
        """Re-anchored documents in one transaction: each observation with its new ``T_map_cam``
        (its map box re-indexed), the instances rebuilt from them, and the uuids that merged away."""
        obs_items = [(o.to_dict(), _aabb(o.box.transformed(T))) for o, T in observations]
        with self.docs.transaction():
            self.docs.put_many(obs_items)
            self.docs.put_many([(i.to_dict(), _aabb(i.box)) for i in instances])
            for uuid in deleted:
                self.docs.delete(uuid)

    # -- the scene graph ----------------------------------------------------------------------

    def graph_synced_seq(self) -> int:
        """The document change the scene graph has caught up to (a version for caches)."""
        return int(self.graph.synced_seq(self.kb_id))

    def graph_in_sync(self) -> bool:
        """Whether the scene graph holds every committed document change."""
        return self.graph_synced_seq() >= self.docs.seq
