"""Re-anchor the background layer of a knowledge base with an optimised trajectory.

Reads every background instance and its observations, recomputes the instances with
``hiper_cli.perceive.background.reanchor`` (each observation takes the pose at its stamp) and
writes the instances, the observations' map boxes and the deletions in one transaction. It
runs perception over stored data, so it sits beside ``pipeline`` above both ``perceive`` and
``graph``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph import KnowledgeBase
from hiper_cli.model import Observation
from hiper_cli.perceive.background import reanchor
from hiper_cli.perceive.logs import Trajectory

__all__ = ["ReanchorSummary", "reanchor_kb", "reanchor_with_poses"]


@dataclass(frozen=True)
class ReanchorSummary:
    """What one re-anchoring did (``to_dict`` is the ``--json`` form).

    ``deleted``: uuids of instances the new poses merged into others; ``unchanged``: uuids
    of instances whose box did not move; ``shift_*_m``: how far the recomputed instance centres
    moved; ``written``: False for a dry run.
    """

    instances: int
    observations: int
    deleted: tuple[str, ...]
    unchanged: tuple[str, ...]
    shift_mean_m: float
    shift_max_m: float
    written: bool
    kb: str = ""
    poses: str = ""

    @property
    def merged(self) -> int:
        return len(self.deleted)

    def to_dict(self) -> dict[str, Any]:
        return {"instances": self.instances, "observations": self.observations, "merged": self.merged,
                "deleted": list(self.deleted), "unchanged": list(self.unchanged),
                "shift_mean_m": self.shift_mean_m, "shift_max_m": self.shift_max_m, "written": self.written,
                "kb": self.kb, "poses": self.poses}


def reanchor_with_poses(kb: str, poses: Path, *, kb_docs: Path | None = None, max_dt_s: float = 0.05,
                        write: bool = True) -> ReanchorSummary:
    """``hiper reanchor`` in one call: read the TUM trajectory ``poses``, re-anchor knowledge base ``kb``."""
    from hiper_cli.graph import open_kb
    from hiper_cli.perceive.logs import read_tum_trajectory

    trajectory = read_tum_trajectory(poses)
    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        summary = reanchor_kb(knowledge, trajectory, max_dt_s=max_dt_s, write=write)
    return replace(summary, kb=str(kb), poses=str(poses))


def reanchor_kb(kb: KnowledgeBase, trajectory: Trajectory, *, max_dt_s: float = 0.05,
                write: bool = True) -> ReanchorSummary:
    """Recompute the background layer of ``kb`` with ``trajectory``; return a summary."""
    instances = kb.instances(layer="background")
    observations: dict[str, Observation] = {}
    for inst in instances:
        held = kb.observations_of(inst.uuid)
        inst.observation_uuids = [o.uuid for o in held]
        observations.update((o.uuid, o) for o in held)
    stamps = np.array([o.stamp_s for o in observations.values()])
    poses: dict[str, NDArray[np.float64]] = {}
    if len(stamps):
        T, covered = trajectory.interpolate(stamps, max_extrapolation_s=max_dt_s)
        poses = {u: T[k] for k, u in enumerate(observations) if covered[k]}

    def pose_of(o: Observation) -> NDArray[np.float64] | None:
        return poses.get(o.uuid)

    before = {i.uuid: i.box.center_m for i in instances}
    result = reanchor(instances, observations.values(), pose_of)
    shifts = [float(np.linalg.norm(i.box.center_m - before[i.uuid])) for i in result.instances]
    if write:
        kb.write_reanchored([(o, poses[u]) for u, o in observations.items() if u in poses],
                            result.instances, result.deleted)
        kb.sync_graph()
    return ReanchorSummary(
        instances=len(result.instances), observations=result.observations, deleted=tuple(result.deleted),
        unchanged=tuple(result.unchanged), shift_mean_m=float(np.mean(shifts)) if shifts else 0.0,
        shift_max_m=float(np.max(shifts)) if shifts else 0.0, written=write, kb=kb.location,
    )
