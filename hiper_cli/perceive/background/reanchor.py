"""Re-anchoring: recompute background instances from their observations with new poses.

Observations are stored in the camera frame of the pose they were seen from (``pose_id``).
When a SLAM back end optimises the trajectory (a loop closure), every background instance is
recomputed from its observations moved with the new poses (the same fold merging uses), and
instances that now coincide are merged (Algorithm 2's duplicate rule).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import DataError
from hiper_cli.model import Instance, Observation
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.merge import fold, instance_matches, merge_into, to_map

__all__ = ["ReanchorResult", "reanchor"]


@dataclass
class ReanchorResult:
    """Recomputed instances (same uuids), uuids of duplicates merged away, and counts."""

    instances: list[Instance] = field(default_factory=list)
    deleted: list[str] = field(default_factory=list)
    observations: int = 0
    unchanged: list[str] = field(default_factory=list)


def reanchor(
    instances: Iterable[Instance],
    observations: Iterable[Observation],
    poses: Mapping[int, NDArray[np.float64]] | Callable[[Observation], NDArray[np.float64] | None],
    config: BackgroundConfig | None = None,
) -> ReanchorResult:
    """Recompute every background instance from its observations with new poses.

    ``poses``: pose_id → T_map_cam, or a function giving an observation's T_map_cam (e.g. by
    its stamp in an optimised trajectory; None when it has none). An observation without a
    pose raises ``DataError``; an instance none of whose observations are given keeps its
    geometry (listed in ``unchanged``).
    """
    if callable(poses):
        pose_of = poses
    else:
        table = poses

        def pose_of(o: Observation) -> NDArray[np.float64] | None:
            return table.get(o.pose_id)

    cfg = config or BackgroundConfig()
    by_uuid = {o.uuid: o for o in observations if o.layer == "background"}
    result = ReanchorResult()
    rebuilt: list[Instance] = []
    for inst in instances:
        if inst.layer != "background":
            continue
        obs = [by_uuid[u] for u in inst.observation_uuids if u in by_uuid]
        if not obs:
            result.unchanged.append(inst.uuid)
            rebuilt.append(inst)
            continue
        found = [(o, pose_of(o)) for o in obs]
        missing = sorted({(o.pose_id, round(o.stamp_s, 6)) for o, T in found if T is None})
        if missing:
            more = " ..." if len(missing) > 5 else ""
            raise DataError(
                f"reanchor: no pose for (pose id, stamp) {missing[:5]}{more}; "
                "the trajectory must cover every pose the observations were anchored to"
            )
        moved = [to_map(o, np.asarray(T, dtype=np.float64)) for o, T in found]
        new = fold(moved, cfg, base=inst)
        new.observation_uuids = list(inst.observation_uuids)
        new.confidence = inst.confidence
        new.last_seen_s = max(new.last_seen_s, inst.last_seen_s)  # a sighting (``sighting.py``)
        rebuilt.append(new)
        result.observations += len(obs)
    # instances that the new poses bring together are one (oldest survives)
    rebuilt.sort(key=lambda i: (i.first_seen_s, i.uuid))
    alive: list[Instance] = []
    for inst in rebuilt:
        dup_of = next((a for a in alive if instance_matches(inst, a, cfg)), None)
        if dup_of is None:
            alive.append(inst)
        else:
            merge_into(dup_of, [inst], None, cfg)
            result.deleted.append(inst.uuid)
    result.instances = alive
    return result
