"""A knowledge base built from a ``hiper sim`` log's ground truth, for testing the query layer
against the truth: every truth instance visible in a frame's id image (at least
``MIN_PIXELS`` pixels) becomes an observation of that frame (its truth box at that stamp, in
the camera frame), and its instance carries the truth class, state, box and, for dynamic
instances, the truth track while seen. Perception errors are thereby out of the picture: a
query that disagrees with the truth is the query layer's fault."""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from hiper_cli.graph import open_kb
from hiper_cli.model import Box3D, FrameResult, Instance, Observation
from hiper_cli.perceive.logs.truth import Truth, load_truth

MIN_PIXELS = 6


@dataclass
class TruthKb:
    path: Path
    truth: Truth
    uuid_of: dict[int, str]  # truth id -> instance uuid
    seen: dict[int, list[float]]  # truth id -> stamps at which it was visible
    poses: list[tuple[float, np.ndarray]]  # (stamp, T_map_cam) per frame
    camera: dict[str, float] = field(default_factory=dict)

    def id_of(self, uuid: str) -> int:
        return {u: i for i, u in self.uuid_of.items()}[uuid]

    def box_at(self, truth_id: int, stamp_s: float) -> Box3D:
        inst = self.truth.instances[truth_id]
        pos = self.truth.position_at(truth_id, stamp_s)
        return inst.box if pos is None else Box3D(pos, inst.box.extent_m, inst.box.R)


def _tum(path: Path) -> list[list[str]]:
    return [
        line.split() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")
    ]


def build_truth_kb(log: Path, kb_path: Path) -> TruthKb:
    import json

    truth = load_truth(log)
    rgb = _tum(log / "rgb.txt")
    gt = {float(r[0]): [float(v) for v in r[1:]] for r in _tum(log / "groundtruth.txt")}
    instances: dict[int, Instance] = {}
    seen: dict[int, list[float]] = {}
    poses: list[tuple[float, np.ndarray]] = []
    with open_kb(kb_path) as kb:
        env = kb.environment("house")
        session = kb.start_session(env, str(log), ["truth"])
        for pose_id, (stamp_text, rel) in enumerate(rgb):
            stamp = float(stamp_text)
            tx, ty, tz, qx, qy, qz, qw = gt[stamp]
            T = np.eye(4)
            T[:3, :3] = Rotation.from_quat([qx, qy, qz, qw]).as_matrix()
            T[:3, 3] = (tx, ty, tz)
            poses.append((stamp, T))
            ids, counts = np.unique(truth.load_instance_ids(rel), return_counts=True)
            result = FrameResult()
            T_cam_map = np.linalg.inv(T)
            for tid, n in zip(ids.tolist(), counts.tolist(), strict=True):
                if tid == 0 or n < MIN_PIXELS or tid not in truth.instances:
                    continue
                ti = truth.instances[tid]
                pos = truth.position_at(tid, stamp)
                box_map = ti.box if pos is None else Box3D(pos, ti.box.extent_m, ti.box.R)
                inst = instances.get(tid)
                if inst is None:
                    inst = Instance(
                        ti.layer,
                        ti.class_name,
                        box_map,
                        stamp,
                        stamp,  # type: ignore[arg-type]
                        state=ti.state,
                        confidence=0.9,
                    )  # type: ignore[arg-type]
                    instances[tid] = inst
                obs = Observation(
                    ti.layer,
                    ti.class_name,
                    0.9,
                    stamp,
                    pose_id,  # type: ignore[arg-type]
                    box_map.transformed(T_cam_map),
                    instance_uuid=inst.uuid,
                )
                inst.box, inst.last_seen_s = box_map, stamp
                inst.observation_uuids.append(obs.uuid)
                if ti.state == "dynamic" and pos is not None:
                    rows = truth.tracks[tid]
                    k = int(np.argmin(np.abs(rows[:, 0] - stamp)))
                    inst.data.setdefault("trajectory", []).append([float(v) for v in rows[k]])
                seen.setdefault(tid, []).append(stamp)
                result.observations.append(obs)
                result.instances.append(inst)
            kb.write_frame(session, result, pose_id=pose_id, stamp_s=stamp, T_map_cam=T)
        kb.end_session(session)
    camera = json.loads((log / "camera.json").read_text())
    return TruthKb(kb_path, truth, {tid: i.uuid for tid, i in instances.items()}, seen, poses, camera)


@cache
def house_truth_kb() -> TruthKb:
    """The house log (40 s at 4 Hz, 160×120, seed 4) and its truth KB, built once per test
    session in a temporary directory."""
    from hiper_cli.sim import RenderConfig, SimConfig, simulate

    root = Path(tempfile.mkdtemp(prefix="hiper-query-house-"))
    simulate(
        "house",
        seconds=40,
        seed=4,
        out=root / "log",
        config=SimConfig(
            rate_hz=4, mapping_s=15, render=RenderConfig(width=160, height=120), png_compression=1
        ),
    )
    return build_truth_kb(root / "log", root / "kb.hiper")
