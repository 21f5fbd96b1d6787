"""The place's background cloud: what a new session's log is aligned to.

One voxel cloud (centroids, map frame) per environment, kept in the documents' ``meta`` table
(key ``map_cloud:ENV_UUID``) as zlib-compressed int16 coordinates in ``QUANTUM_M`` steps: about
6 bytes a voxel before compression, some 100-200 kB for a house. Each session adds the voxels
it saw; the cloud grows with new space, not with time.
"""

from __future__ import annotations

import base64
import zlib

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph.documents import DocumentStore

__all__ = ["QUANTUM_M", "drop_map_cloud", "load_map_cloud", "store_map_cloud"]

QUANTUM_M = 0.005  # int16 steps: ±163 m around the map origin
_KEY = "map_cloud:{}"


def store_map_cloud(docs: DocumentStore, env_uuid: str, points_m: NDArray[np.float64]) -> int:
    """Replace the environment's cloud (inside a transaction); returns the bytes stored."""
    q = np.clip(np.round(np.asarray(points_m, dtype=np.float64) / QUANTUM_M), -32767, 32767).astype("<i2")
    text = base64.b64encode(zlib.compress(q.tobytes(), 6)).decode("ascii")
    docs.set_meta(_KEY.format(env_uuid), text)
    return len(text)


def load_map_cloud(docs: DocumentStore, env_uuid: str) -> NDArray[np.float64] | None:
    text = docs.meta(_KEY.format(env_uuid))
    if text is None:
        return None
    raw = np.frombuffer(zlib.decompress(base64.b64decode(text)), dtype="<i2")
    return raw.reshape(-1, 3).astype(np.float64) * QUANTUM_M


def drop_map_cloud(docs: DocumentStore, env_uuid: str) -> None:
    """Forget the environment's cloud (inside a transaction): its only session was dropped."""
    docs.drop_meta(_KEY.format(env_uuid))
