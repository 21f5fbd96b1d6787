"""A static object's observed surface: a uniform sample of the points of all the blobs it was
seen as (map frame), kept per track while a session runs and stored with the instance
(``data["surface_map"]``).

A later session of the place aims its empty-place rays at these points (``vacated.py``): a
ray to a point the object's surface held either meets the surface there (the object stayed)
or passes on (it went). The points of the box, which the object fills only in part, cannot tell
a table (its box mostly air under the top) from a place seen empty.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["SAMPLE_POINTS", "SurfaceSamples"]

FloatArray = NDArray[np.float64]
SAMPLE_POINTS = 32  # kept per object: a uniform sample over all its blobs
PER_BLOB = 4  # points offered per blob, evenly spaced over its points


class SurfaceSamples:
    """Per track uuid, ``SAMPLE_POINTS`` of its blobs' points drawn uniformly (reservoir
    sampling, seeded: a run gives the same sample every time)."""

    def __init__(self, seed: int = 0) -> None:
        self._points: dict[str, list[FloatArray]] = {}
        self._offered: dict[str, int] = {}
        self._rng = np.random.default_rng(seed)

    def add(self, uuid: str, points_map: FloatArray) -> None:
        if len(points_map) == 0:
            return
        picks = points_map[np.linspace(0, len(points_map) - 1, min(PER_BLOB, len(points_map))).astype(int)]
        kept = self._points.setdefault(uuid, [])
        for point in picks:
            n = self._offered.get(uuid, 0)
            self._offered[uuid] = n + 1
            if len(kept) < SAMPLE_POINTS:
                kept.append(np.asarray(point, dtype=np.float64))
            elif (j := int(self._rng.integers(n + 1))) < SAMPLE_POINTS:
                kept[j] = np.asarray(point, dtype=np.float64)

    def keep(self, uuids: set[str]) -> None:
        """Forget every track but ``uuids`` (those that may still be seen or closed again)."""
        for uuid in [u for u in self._points if u not in uuids]:
            del self._points[uuid], self._offered[uuid]

    def of(self, uuid: str) -> list[list[float]] | None:
        """The sample of ``uuid`` as rounded lists (mm), None when it has none."""
        kept = self._points.get(uuid)
        return [[round(float(v), 3) for v in p] for p in kept] if kept else None
