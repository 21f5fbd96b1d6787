"""Knowledge bases with known truth for the analyze tests: tracks written as instances."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from hiper_cli.graph.kb import KnowledgeBase, open_kb
from hiper_cli.model import Box3D, Instance


def track_instance(
    rows: np.ndarray, class_name: str = "person", extent=(0.5, 0.4, 1.7), bottom_m: float = 0.0
) -> Instance:
    """A closed foreground instance whose trajectory is ``rows`` (N, 7); ``dynamic`` when it
    travelled half a metre, as the tracker's state (``dynamic_travel_m``)."""
    rows = np.asarray(rows, dtype=np.float64).copy()
    travelled_m = float(np.ptp(rows[:, 1:3], axis=0).max()) if len(rows) else 0.0
    rows[:, 3] = bottom_m + extent[2] / 2.0  # the tracked centre: the box's
    center = np.array([rows[-1, 1], rows[-1, 2], rows[-1, 3]])
    return Instance(
        "foreground",
        class_name,
        Box3D(center, np.asarray(extent, dtype=np.float64)),
        float(rows[0, 0]),
        float(rows[-1, 0]),
        state="dynamic" if travelled_m > 0.5 else "static",
        data={"trajectory": rows.tolist(), "closed": True},
    )


def walk_stand_rows(
    rng: np.random.Generator,
    t0: float,
    speed_mps: float,
    walk_s: float,
    stand_s: float,
    noise_mps: float = 0.03,
    hz: float = 10.0,
    start=(0.0, 0.0),
) -> np.ndarray:
    """Rows of someone who walks along +x at ``speed_mps`` then stands; velocity noise per axis."""
    n_walk, n_stand = int(walk_s * hz), int(stand_s * hz)
    t = t0 + np.arange(n_walk + n_stand) / hz
    v = np.zeros((len(t), 3))
    v[:n_walk, 0] = speed_mps
    x = start[0] + np.concatenate([np.arange(n_walk) / hz * speed_mps, np.full(n_stand, walk_s * speed_mps)])
    y = np.full(len(t), start[1])
    v[:, :2] += rng.normal(0.0, noise_mps, size=(len(t), 2))
    return np.column_stack([t, x, y, np.full(len(t), 0.85), v])


def write_instances(path: Path, instances: Sequence[Instance], env: str = "test") -> KnowledgeBase:
    kb = open_kb(path)
    e = kb.environment(env)
    kb.put_documents([i.to_dict() for i in instances], env_uuid=e.uuid)
    return kb


def hospital_people_rows(
    seconds: float = 120.0, seed: int = 1, hz: float = 5.0
) -> tuple[list[np.ndarray], object]:
    """True trajectories of the hospital world's people (the simulator's crowd, no rendering)."""
    from hiper_cli.sim.people import Crowd
    from hiper_cli.sim.worlds import make_world

    world = make_world("hospital", seed)
    crowd = Crowd(world, seed)
    rows: list[list[list[float]]] = [[] for _ in crowd.specs]
    for k in range(int(seconds * hz)):
        crowd.step(1.0 / hz)
        for i in range(len(crowd.specs)):
            x, y = crowd.pos[i]
            vx, vy = crowd.vel[i]
            rows[i].append([k / hz, float(x), float(y), 0.85, float(vx), float(vy), 0.0])
    return [np.asarray(r) for r in rows], world
