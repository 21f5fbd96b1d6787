"""Typed reads of a knowledge base, so that no caller (pipeline, query layer, README) reaches
into its document store. A mixin of ``KnowledgeBase``: robot poses, sessions, observations
and their links, analyses, spatial prefilters and bound SPARQL."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph.documents import DocumentStore, Session
from hiper_cli.graph.sparql_safety import DEFAULT_TIMEOUT_S
from hiper_cli.model import Analysis, Observation

__all__ = ["KbReads", "ObservationPoint", "RobotPose"]


@dataclass(frozen=True)
class RobotPose:
    """A recorded camera pose: ``T_map_cam`` (4×4, camera optical frame: z forward) at
    ``stamp_s``, frame ``pose_id`` of session ``session_id``."""

    stamp_s: float
    T_map_cam: NDArray[np.float64]
    session_id: int | None = None
    pose_id: int | None = None

    @property
    def position_map_m(self) -> NDArray[np.float64]:
        return np.asarray(self.T_map_cam[:3, 3], dtype=np.float64)

    @property
    def yaw_rad(self) -> float:
        """Heading of the optical axis projected onto the map's xy plane."""
        forward = self.T_map_cam[:3, 2]
        return math.atan2(float(forward[1]), float(forward[0]))


@dataclass(frozen=True)
class ObservationPoint:
    """Where and when one observation was made: its map-box centre (m) and stamp (s)."""

    uuid: str
    instance_uuid: str | None
    stamp_s: float
    center_map_m: tuple[float, float, float]


class KbReads:
    """Reads over ``self.docs`` and ``self.graph`` that return model types."""

    docs: DocumentStore
    graph: Any

    def sessions(self, env_uuid: str | None = None) -> list[Session]:
        """The perception sessions (optionally of one environment), oldest first."""
        return [s for s in self.docs.sessions() if env_uuid is None or s.env_uuid == env_uuid]

    def robot_pose(self, at_s: float | None = None) -> RobotPose | None:
        """The last recorded camera pose at or before ``at_s`` (None: the last of all)."""
        row = self.docs.pose_before(at_s)
        if row is None:
            return None
        session_id, pose_id, stamp_s, T = row
        return RobotPose(stamp_s, np.asarray(T, dtype=np.float64), session_id, pose_id)

    def stamp_span(self) -> tuple[float, float] | None:
        """(first, last) stamp known to the knowledge base (poses and observations)."""
        return self.docs.stamp_span()

    def observations_of(self, instance_uuid: str) -> list[Observation]:
        """The observations an instance was formed from, in time order."""
        return [Observation.from_dict(d) for d in self.docs.observations_of(instance_uuid)]

    def observation_uuids_of(self, instance_uuids: Sequence[str]) -> dict[str, list[str]]:
        """instance uuid -> its observations' uuids (the evidence), oldest first."""
        return self.docs.observation_links(instance_uuids)

    def observation_stamps_of(self, instance_uuid: str) -> list[float]:
        """The stamps of an instance's observations, with those its summarised stretches in
        view stand for (``compact.py``)."""
        from hiper_cli.graph.spans import VIEW_SPANS, span_stamps

        stamps = self.docs.observation_stamps(instance_uuid)
        doc = self.docs.get(instance_uuid)
        if doc is not None and (doc.get("data") or {}).get(VIEW_SPANS):
            stamps = sorted([*stamps, *span_stamps(doc)])
        return stamps

    def observations_near(
        self, lo: Sequence[float], hi: Sequence[float], class_name: str | None = None
    ) -> list[ObservationPoint]:
        """Observations whose map-box centre lies in the axis-aligned box [lo, hi] (m)."""
        return [
            ObservationPoint(u, i, t, (x, y, z))
            for u, i, t, x, y, z in self.docs.observation_points_in(lo, hi, class_name)
        ]

    def analyses(self, kind: str | None = None, class_name: str | None = None) -> list[Analysis]:
        """Learned features (``hiper analyze``), newest window last."""
        return [
            a
            for a in (Analysis.from_dict(d) for d in self.docs.find(type="analysis", class_name=class_name))
            if kind is None or a.kind == kind
        ]

    def query_bound(self, sparql: str, bindings: Mapping[str, Any]) -> list[dict[str, Any]]:
        """SPARQL SELECT with variables bound to values (never pasted into the text)."""
        return list(self.graph.query(sparql, bindings))

    def run_readonly(
        self, sparql: str, media_type: str = "application/sparql-results+json",
        timeout_s: float | None = DEFAULT_TIMEOUT_S,
    ) -> tuple[bytes, str]:
        """Any read-only SPARQL query over all graphs, serialised; updates, ``SERVICE`` and a
        query past ``timeout_s`` refused."""
        body, media = self.graph.run_readonly(sparql, media_type, timeout_s)
        return bytes(body), str(media)
