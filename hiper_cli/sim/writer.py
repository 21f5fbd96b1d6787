"""``simulate``: drive the robot through a world, render every frame, write the log and its truth.

Timeline: stamps ``k / rate_hz`` from 0; the mapping phase (no people, carts still) lasts
``mapping_s``, then the operation phase adds the people and lets the carts move. Output:
the TUM RGB-D folder (written by ``TumWriter``) plus ``gt/`` as specified in
``hiper_cli.perceive.logs.truth``. A ``sensor`` profile other than ``ideal`` records the
exact render as that sensor would (``hiper_cli.sensor``): the log's ``groundtruth.txt`` is
then the drifting pose estimate and ``gt/groundtruth.txt`` the exact trajectory.
"""

from __future__ import annotations

import csv
import json
import math
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from hiper_cli.errors import ConfigError, LogError
from hiper_cli.model import Box3D
from hiper_cli.sensor import SensorProfile, get_profile
from hiper_cli.sensor.colour import image_flow_px_per_s
from hiper_cli.sensor.degrade import degrade_frame, pose_error, write_trajectory
from hiper_cli.sensor.poses import PoseSource
from hiper_cli.sim.meshes import Mesh, human, rot_z
from hiper_cli.sim.noise import NoiseModel, detect
from hiper_cli.sim.people import Carts, Crowd, SocialForceConfig
from hiper_cli.sim.render import DepthNoise, RenderConfig, Renderer
from hiper_cli.sim.route import Route, RouteConfig, plan_route
from hiper_cli.sim.scene_truth import DynamicTruth, SceneTruthRecorder, StaticTruth
from hiper_cli.sim.worlds import World, make_world

__all__ = ["SimConfig", "SimResult", "simulate"]

if TYPE_CHECKING:
    from hiper_cli.types import Frame

_STRIDES = 9  # leg poses per person, from -1 to 1
_POSE_STREAM, _SENSOR_STREAM = 0x5E50, 0x5E51  # the sensor's random streams, apart from the render's


@dataclass(frozen=True)
class SimConfig:
    """Everything that shapes a log besides the world, its seed and its length."""

    rate_hz: float = 30.0
    mapping_s: float | None = None  # default: a third of the log, at most 60 s
    render: RenderConfig = field(default_factory=RenderConfig)
    route: RouteConfig = field(default_factory=RouteConfig)
    people: SocialForceConfig = field(default_factory=SocialForceConfig)
    noise: NoiseModel = field(default_factory=NoiseModel)
    png_compression: int = 3
    sensor: str = "ideal"  # a hiper_cli.sensor profile; not ideal: it replaces render.noise

    @classmethod
    def from_flat(
        cls, *, rate_hz: float = 30.0, mapping_s: float | None = None, width_px: int = 640,
        height_px: int = 480, max_range_m: float = 5.0, speed_mps: float = 0.6, depth_noise: bool = True,
        miss_rate: float = 0.1, jitter_frac: float = 0.05, false_positives_per_image: float = 0.05,
        confusion_rate: float = 0.03,
        png_compression: int = 3, sensor: str = "ideal",
    ) -> SimConfig:
        """The configuration from the flat choices ``hiper sim`` offers (the rest at defaults)."""
        return cls(
            rate_hz=rate_hz, mapping_s=mapping_s, png_compression=png_compression, sensor=sensor,
            render=RenderConfig(width=width_px, height=height_px, max_range_m=max_range_m,
                                noise=DepthNoise() if depth_noise else DepthNoise.off()),
            route=RouteConfig(speed_mps=speed_mps),
            noise=NoiseModel(miss_rate=miss_rate, jitter_frac=jitter_frac, confusion_rate=confusion_rate,
                             false_positives_per_image=false_positives_per_image),
        )

    def mapping_for(self, seconds: float) -> float:
        if self.mapping_s is None:
            return min(seconds / 3.0, 60.0)
        return self.mapping_s


@dataclass(frozen=True)
class SimResult:
    out: Path
    world: str
    seed: int
    frames: int
    seconds: float
    mapping_s: float
    instances: int
    people: int
    elapsed_s: float
    sensor: str = "ideal"

    @property
    def frames_per_s(self) -> float:
        return self.frames / self.elapsed_s if self.elapsed_s > 0 else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "out": str(self.out),
            "world": self.world,
            "seed": self.seed,
            "frames": self.frames,
            "seconds": self.seconds,
            "mapping_s": self.mapping_s,
            "instances": self.instances,
            "people": self.people,
            "elapsed_s": round(self.elapsed_s, 3),
            "frames_per_s": round(self.frames_per_s, 2),
            "sensor": self.sensor,
        }


def _blocked(route: Route, route_t: float, people_xy: np.ndarray) -> bool:
    """True when a person stands within the stop distance in front of the robot (±30°)."""
    if len(people_xy) == 0:
        return False
    x, y, yaw = route.state_at(route_t)
    d = people_xy - np.array([x, y])
    dist = np.linalg.norm(d, axis=1)
    ahead = d @ np.array([math.cos(yaw), math.sin(yaw)]) > math.cos(math.radians(30.0)) * dist
    return bool(np.any((dist < route.config.stop_distance_m) & ahead))


def _person_box(height_m: float, radius_m: float, x: float, y: float) -> Box3D:
    return Box3D(np.array([x, y, height_m / 2.0]), np.array([2 * radius_m, 2 * radius_m, height_m]))


def _advance(route: Route, route_t: float, waited_s: float, dt: float, people_xy: np.ndarray,
             max_wait_s: float) -> tuple[float, float]:
    """The robot's (route time, time waited) after ``dt``: it waits while someone is in its way,
    up to ``max_wait_s``, then goes on."""
    in_way = _blocked(route, route_t, people_xy)
    if in_way and waited_s < max_wait_s:
        return route_t, waited_s + dt
    return route_t + dt, 0.0 if not in_way else waited_s


@dataclass
class _MoverTruth:
    """What the moving bodies (people, carts) leave in ``gt/``: each one's first box, its
    centre over time and the rows of tracks.csv."""

    first_box: dict[int, Box3D] = field(default_factory=dict)
    centres: dict[int, list[list[float]]] = field(default_factory=dict)  # id: [t, x, y, z] rows
    tracks_rows: list[list[Any]] = field(default_factory=list)

    def add(self, body_id: int, t: float, box: Box3D, vx: float, vy: float) -> None:
        self.first_box.setdefault(body_id, box)
        self.centres.setdefault(body_id, []).append([float(t), *box.center_m])
        self.tracks_rows.append([f"{t:.6f}", body_id, *(f"{v:.5f}" for v in (*box.center_m, vx, vy, 0.0))])


def _people_meshes(crowd: Crowd) -> tuple[list[list[Mesh]], list[float]]:
    """Each person's mesh in ``_STRIDES`` leg poses, and their horizontal radius in metres."""
    people_meshes: list[list[Mesh]] = []
    radius: list[float] = []
    for spec in crowd.specs:
        poses = [
            human(spec.height_m, spec.skin, spec.shirt, spec.trousers, spec.hair, s)
            for s in np.linspace(-1.0, 1.0, _STRIDES)
        ]
        people_meshes.append(poses)
        radius.append(max(float(np.hypot(m.vertices[:, 0], m.vertices[:, 1]).max()) for m in poses))
    return people_meshes, radius


def _people_at(t: float, crowd: Crowd, people_meshes: list[list[Mesh]], radius: list[float],
               movers: _MoverTruth) -> list[tuple[int, Mesh]]:
    """The people's meshes where they are at ``t``, their truth recorded in ``movers``."""
    dynamic: list[tuple[int, Mesh]] = []
    for i, spec in enumerate(crowd.specs):
        px, py = crowd.pos[i]
        s = round((crowd.stride(i) + 1.0) / 2.0 * (_STRIDES - 1))
        dynamic.append((spec.id, people_meshes[i][s].transformed(rot_z(crowd.heading[i], (px, py, 0.0)))))
        vx, vy = crowd.vel[i]
        movers.add(spec.id, t, _person_box(spec.height_m, radius[i], float(px), float(py)), vx, vy)
    return dynamic


def _carts_at(t: float, carts: Carts, movers: _MoverTruth) -> list[tuple[int, Mesh]]:
    """The carts' meshes where they are at ``t``, their truth recorded in ``movers``."""
    dynamic: list[tuple[int, Mesh]] = []
    for i, cspec in enumerate(carts.specs):
        cx, cy = carts.pos[i]
        mesh = cspec.mesh.transformed(rot_z(cspec.yaw_rad, (cx, cy, 0.0)))
        dynamic.append((cspec.id, mesh))
        lo, hi = mesh.bounds()
        vx, vy = carts.vel[i]
        movers.add(cspec.id, t, Box3D((lo + hi) / 2.0, hi - lo), vx, vy)
    return dynamic


def simulate(
    world: str | World,
    seconds: float,
    seed: int,
    out: str | Path,
    config: SimConfig | None = None,
    *,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
    T_log_map: np.ndarray | None = None,
) -> SimResult:
    """Write a simulated log of ``seconds`` to ``out``; the same arguments give identical files.

    ``T_log_map``: the log's poses are written in this frame (a session's own odometry frame,
    ``hiper sim --sessions``); the truth in ``gt/`` stays in the world's map frame."""
    import cv2

    from hiper_cli.perceive.logs import TumWriter
    from hiper_cli.types import Frame

    cfg = config or SimConfig()
    if seconds <= 0 or cfg.rate_hz <= 0:
        raise ConfigError(f"seconds={seconds}, rate_hz={cfg.rate_hz}: both must be positive")
    profile = get_profile(cfg.sensor)
    sensor = _SensorRecorder(profile, seed)
    if profile.name != "ideal":
        cfg = replace(cfg, render=replace(cfg.render, noise=DepthNoise.off()))
    w = make_world(world, seed) if isinstance(world, str) else world
    mapping_s = cfg.mapping_for(seconds)
    if not 0 <= mapping_s <= seconds:
        raise ConfigError(f"mapping phase {mapping_s} s: expected between 0 and the log length {seconds} s")
    n_frames = max(1, math.floor(seconds * cfg.rate_hz + 1e-9))
    stamps = np.arange(n_frames) / cfg.rate_hz
    route = plan_route(w, float(stamps[-1]) + 1.0, cfg.route)
    renderer = Renderer([(o.id, o.mesh) for o in w.objects], cfg.render)
    crowd = Crowd(w, seed, cfg.people)
    carts = Carts(w.carts, seed)

    people_meshes, radius = _people_meshes(crowd)
    classes = {o.id: o.class_name for o in w.objects}
    classes.update({s.id: "person" for s in crowd.specs})
    classes.update({c.id: "cart" for c in carts.specs})
    picture_ids = frozenset(o.id for o in w.objects if o.class_name in ("picture", "tv"))

    root = Path(out)
    writer = TumWriter(root, renderer.camera, overwrite=overwrite)
    gt = root / "gt"
    (gt / "instance_ids").mkdir(parents=True, exist_ok=True)
    for folder in ("rgb", "depth", "gt/instance_ids"):  # with overwrite: drop images of an older log
        for stale in (root / folder).glob("*.png"):
            stale.unlink(missing_ok=True)  # another run may have removed it
    movers = _MoverTruth()
    all_ids = [o.id for o in w.objects] + [s.id for s in crowd.specs] + [c.id for c in carts.specs]
    scene_truth = SceneTruthRecorder(renderer.camera, cfg.render.max_range_m, max(all_ids, default=0) + 1)
    png = [cv2.IMWRITE_PNG_COMPRESSION, int(cfg.png_compression)]
    op_start = next((k for k, t in enumerate(stamps) if t >= mapping_s - 1e-9), n_frames)
    started = time.perf_counter()

    def _save(frame: Frame, ids: np.ndarray) -> None:
        stem = writer.write(frame)
        if not cv2.imwrite(str(gt / "instance_ids" / f"{stem}.png"), ids, png):
            raise LogError(f"{gt / 'instance_ids'}: cannot write the id image; check the disk")

    with ThreadPoolExecutor(max_workers=1) as pool, writer, (gt / "detections.jsonl").open("w") as det_fh:
        pending: Future[None] | None = None
        prev_t = 0.0
        route_t = 0.0  # how far along its route the robot is; it waits while someone is in its way
        waited_s = 0.0
        for k, t in enumerate(stamps):
            operating = k >= op_start
            dt = float(t - prev_t)
            prev_t = float(t)
            if k > 0:
                people_xy = crowd.pos if operating else np.zeros((0, 2))
                route_t, waited_s = _advance(route, route_t, waited_s, dt, people_xy, cfg.route.max_wait_s)
            x, y, _ = route.state_at(route_t)
            if operating and k > op_start:
                crowd.step(dt, (x, y), carts.footprints())
            carts.step(dt, operating and k > op_start)
            dynamic: list[tuple[int, Mesh]] = []
            if operating:
                dynamic += _people_at(float(t), crowd, people_meshes, radius, movers)
            dynamic += _carts_at(float(t), carts, movers)
            T = route.pose_at(route_t)
            rng = np.random.default_rng([seed, k])
            image = renderer.render(T, dynamic, rng)
            scene_truth.add(float(t), image.hit_ids, image.true_z_m, image.normal_cam, T,
                            (i for i, _ in dynamic))
            detections = detect(image.ids, classes, cfg.noise, rng, picture_ids)
            det_fh.write(json.dumps({"stamp_s": round(float(t), 6), "detections": detections}) + "\n")
            frame = sensor.record(Frame(
                stamp_s=float(t),
                rgb=image.rgb,
                depth_m=image.depth_m,
                camera=renderer.camera,
                T_map_cam=T if T_log_map is None else T_log_map @ T,
                pose_id=k,
                source=f"sim:{w.name}:{k}",
            ))
            if pending is not None:
                pending.result()
            pending = pool.submit(_save, frame, image.ids)
            if progress is not None:
                progress(k + 1, n_frames)
        if pending is not None:
            pending.result()

    elapsed = time.perf_counter() - started
    with (gt / "tracks.csv").open("w", newline="") as fh:
        out_csv = csv.writer(fh)
        out_csv.writerow(["stamp_s", "id", "x", "y", "z", "vx", "vy", "vz"])
        out_csv.writerows(movers.tracks_rows)
    (gt / "noise.json").write_text(json.dumps(cfg.noise.to_dict(), indent=2) + "\n")
    sensor.write_truth(gt)
    (gt / "world.json").write_text(
        json.dumps(_world_doc(w, crowd, carts, movers.first_box, cfg, stamps, op_start), indent=1) + "\n"
    )
    moving = [(s.id, s.name, "person", s.speed_mps) for s in crowd.specs]
    moving += [(c.id, c.name, "cart", c.speed_mps) for c in carts.specs]
    scene_truth.write(
        gt, w.name, seed, cfg.rate_hz,
        [StaticTruth(o.id, o.name, o.class_name, o.mesh, o.plane) for o in w.objects],
        [DynamicTruth(i, name, cls, np.asarray(movers.centres[i]), movers.first_box[i].extent_m, float(speed))
         for i, name, cls, speed in moving if i in movers.centres],
    )
    return SimResult(
        root,
        w.name,
        seed,
        n_frames,
        float(seconds),
        mapping_s,
        len(w.objects) + len(crowd.specs) + len(carts.specs),
        len(crowd.specs),
        elapsed,
        profile.name,
    )


class _SensorRecorder:
    """Turns each rendered frame into what ``profile``'s sensor records; keeps the true poses."""

    def __init__(self, profile: SensorProfile, seed: int) -> None:
        self.profile = profile
        self.seed = seed
        self.poses = PoseSource(profile, np.random.default_rng([seed, _POSE_STREAM]))
        self.stamps_s: list[float] = []
        self.T_true: list[np.ndarray] = []
        self.T_est: list[np.ndarray] = []

    def record(self, frame: Frame) -> Frame:
        if self.profile.name == "ideal":
            return frame
        flow = np.zeros(2)
        if self.T_true:
            flow = image_flow_px_per_s(self.T_true[-1], frame.T_map_cam, frame.stamp_s - self.stamps_s[-1],
                                       frame.camera, frame.depth_m)
        rng = np.random.default_rng([self.seed, frame.pose_id, _SENSOR_STREAM])
        out = degrade_frame(frame, flow, self.profile, rng)
        T_est = self.poses.next(frame.T_map_cam)
        self.stamps_s.append(frame.stamp_s)
        self.T_true.append(frame.T_map_cam)
        self.T_est.append(T_est)
        return replace(out, T_map_cam=T_est)

    def write_truth(self, gt: Path) -> None:
        """``gt/groundtruth.txt`` (the exact trajectory) and ``gt/sensor.json``; nothing when ideal."""
        if self.profile.name == "ideal":
            return
        true, est = np.array(self.T_true), np.array(self.T_est)
        write_trajectory(gt / "groundtruth.txt", np.array(self.stamps_s), true)
        (gt / "sensor.json").write_text(json.dumps(
            {"profile": self.profile.to_dict(), "seed": self.seed, "pose_error": pose_error(true, est)},
            indent=2) + "\n")


def _world_doc(
    w: World,
    crowd: Crowd,
    carts: Carts,
    first_box: dict[int, Box3D],
    cfg: SimConfig,
    stamps: np.ndarray,
    op_start: int,
) -> dict[str, Any]:
    instances: list[dict[str, Any]] = [
        {
            "id": o.id,
            "name": o.name,
            "class": o.class_name,
            "layer": o.layer,
            "state": "static",
            "box": o.box.to_dict(),
            "plane": list(o.plane) if o.plane else None,
            "speed_mps": None,
        }
        for o in w.objects
    ]
    for spec in crowd.specs:
        if spec.id in first_box:
            instances.append(
                {
                    "id": spec.id,
                    "name": spec.name,
                    "class": "person",
                    "layer": "foreground",
                    "state": "dynamic",
                    "box": first_box[spec.id].to_dict(),
                    "plane": None,
                    "speed_mps": spec.speed_mps,
                }
            )
    for cspec in carts.specs:
        instances.append(
            {
                "id": cspec.id,
                "name": cspec.name,
                "class": "cart",
                "layer": "foreground",
                "state": "dynamic",
                "box": first_box[cspec.id].to_dict(),
                "plane": None,
                "speed_mps": cspec.speed_mps,
            }
        )
    last = float(stamps[-1])
    phases = []
    if op_start > 0:
        phases.append({"name": "mapping", "t_start_s": 0.0, "t_end_s": float(stamps[op_start - 1])})
    if op_start < len(stamps):
        phases.append({"name": "operation", "t_start_s": float(stamps[op_start]), "t_end_s": last})
    return {
        "world": w.name,
        "seed": w.seed,
        "rate_hz": cfg.rate_hz,
        "bounds_m": list(w.bounds),
        "ceiling_m": w.ceiling_m,
        "walls_xy": [list(r) for r in w.walls],
        "robot": {
            "speed_mps": cfg.route.speed_mps,
            "camera_height_m": cfg.route.camera_height_m,
            "camera_pitch_deg": cfg.route.camera_pitch_deg,
        },
        "instances": instances,
        "phases": phases,
    }
