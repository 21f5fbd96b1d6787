"""Re-anchor the background layer of a knowledge base with an optimised trajectory.

Reads every background instance and its observations, recomputes the instances with
``hiper_cli.perceive.background.reanchor`` (each observation takes the pose at its stamp) and
writes the instances, the observations' map boxes and the deletions in one transaction. It
runs perception over stored data, so it sits beside ``pipeline`` above both ``perceive`` and
``graph``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph import KnowledgeBase
from hiper_cli.model import Observation
from hiper_cli.perceive.background import reanchor
from hiper_cli.perceive.logs import Trajectory

__all__ = ["reanchor_kb"]


def _aabb(lo: Any, hi: Any) -> tuple[list[float], list[float]]:
    return [float(v) for v in lo], [float(v) for v in hi]


def reanchor_kb(kb: KnowledgeBase, trajectory: Trajectory, *, max_dt_s: float = 0.05,
                write: bool = True) -> dict[str, Any]:
    """Recompute the background layer of ``kb`` with ``trajectory``; return a summary."""
    instances = kb.instances(layer="background")
    observations: dict[str, Observation] = {}
    for inst in instances:
        docs = kb.docs.observations_of(inst.uuid)
        inst.observation_uuids = [d["uuid"] for d in docs]
        for d in docs:
            observations[d["uuid"]] = Observation.from_dict(d)
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
        obs_items = [(o.to_dict(), _aabb(*o.box.transformed(poses[u]).aabb()))
                     for u, o in observations.items() if u in poses]
        inst_items = [(i.to_dict(), _aabb(*i.box.aabb())) for i in result.instances]
        with kb.docs.transaction():
            kb.docs.put_many(obs_items)
            kb.docs.put_many(inst_items)
            for uuid in result.deleted:
                kb.docs.delete(uuid)
        kb.sync_graph()
    return {
        "instances": len(result.instances),
        "observations": result.observations,
        "merged": len(result.deleted),
        "deleted": result.deleted,
        "unchanged": result.unchanged,
        "shift_mean_m": float(np.mean(shifts)) if shifts else 0.0,
        "shift_max_m": float(np.max(shifts)) if shifts else 0.0,
        "written": write,
    }
