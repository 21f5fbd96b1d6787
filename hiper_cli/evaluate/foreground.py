"""The paper's Table III (foreground long-term perception) measured on a ``hiper sim`` log.

``evaluate_foreground(log)`` runs the background (the ``background`` stage when this version
of hiper has one, else the ground-truth background boxes) and the foreground stage over the
log with ``run_stages``, and compares with the ground truth in ``LOG/gt``:

- each observation gets the truth instance id that most of its sampled pixels
  (``data["pixels_uv"]``) show in ``gt/instance_ids``; each instance the id most of its
  observations got. Truth tables are background, but a ``table`` observation (a top the
  foreground found where the background mapped none) may take a true table's id, as
  ``hiper eval scene`` scores it (``FOUND_BOTH_WAYS``);
- classification: an instance is a TP when its class equals the class of its truth instance,
  else an FP (also when it covers no foreground truth instance); ``unknown`` instances are
  counted apart;
- localisation: per observation of a foreground truth instance (a table's is its top, which
  the background maps), the distance between the blob centre and the centre of the
  truth instance's visible points in the same frame (what the sensor could see), over the
  classified observations (the Table III row), over all, and horizontally; per instance, the
  distance between the tracked centre and the true box centre at the same stamps (this one
  includes the bias of seeing only the near side of an object);
- people: dynamic ratio and |v| statistics over the trajectory rows of person instances;
  the mean speed of moving people against the truth's speed at the same stamps;
- identity switches: how often the instance observing a truth instance changes;
- time: the foreground stage per frame, and frames per second end to end (reading the log in
  a prefetch thread, background and foreground; the evaluation's own bookkeeping excluded).

The ablation (``ablation=True``) runs the foreground again without background filtering (the
paper's C4) and reports the slowdown.
"""

from __future__ import annotations

import itertools
import json
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.evaluate.result import Evaluation
from hiper_cli.evaluate.scene import FOUND_BOTH_WAYS
from hiper_cli.model import Analysis, Instance, Observation, TrackTrajectory
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.logs.truth import Truth, load_truth
from hiper_cli.perceive.runner import prefetch, run_stages
from hiper_cli.perceive.stage import FrameResult, Stage, World, make_stage
from hiper_cli.types import Frame

__all__ = [
    "BACKGROUND_SOURCES",
    "PAPER_TABLE_III",
    "TRUE_PEOPLE_SPEED_MPS",
    "ForegroundReport",
    "ForegroundRun",
    "PerceptionScore",
    "evaluate_foreground",
    "parse_settings",
    "perceive_and_score",
    "prefetch",
    "run_foreground",
    "score_run",
]

# House, hospital, office columns of the paper's Table III (and the C4 ablation of section VI).
PAPER_TABLE_III: dict[str, Any] = {
    "detect_time_s": {"house": [0.047, 0.054], "hospital": [0.118, 0.122], "office": [0.101, 0.026]},
    "classification_tp_fp": {"house": [42, 3], "hospital": [297, 8], "office": [66, 4]},
    "fp_share": {"house": 3 / 45, "hospital": 8 / 305, "office": 4 / 70},
    "sum_i_o": {"house": [45, 61489], "hospital": [385, 158919], "office": [70, 16262]},
    "localisation_m": {"house": [0.014, 0.018], "hospital": [0.015, 0.012], "office": [0.020, 0.011]},
    "people_dynamic_ratio": {"house": 0.268, "hospital": 0.180, "office": 0.056},
    "people_speed_mps": {"house": [0.126, 0.060], "hospital": [0.157, 0.087], "office": [0.101, 0.191]},
    "people_speed_ci_mps": {"house": [0.051, 0.288], "hospital": [0.037, 0.580], "office": [0.030, 0.277]},
    "frames_per_s": 10.0,
    "ablation_latency_increase": 0.69,
}
TRUE_PEOPLE_SPEED_MPS = 0.6
BACKGROUND_SOURCES = ("auto", "stage", "truth")


@dataclass
class ForegroundRun:
    """Everything one pass over the log produced, kept for scoring."""

    world: World
    observations: dict[str, Observation] = field(default_factory=dict)
    obs_truth_id: dict[str, int | None] = field(default_factory=dict)
    obs_visible_error_m: dict[str, float] = field(default_factory=dict)
    obs_visible_error_xy_m: dict[str, float] = field(default_factory=dict)
    obs_frame: dict[str, int] = field(default_factory=dict)
    foreground_times_s: list[float] = field(default_factory=list)
    frames: int = 0
    wall_s: float = 0.0
    background_source: str = ""
    points: list[float] = field(default_factory=list)
    points_after_background: list[float] = field(default_factory=list)

    @property
    def frames_per_s(self) -> float:
        """Frames over the wall time of the run, reading included, scoring excluded."""
        return self.frames / self.wall_s if self.wall_s > 0 else 0.0


def _truth_background(truth: Truth) -> dict[str, Instance]:
    out: dict[str, Instance] = {}
    for t in truth.instances.values():
        if t.layer == "background":
            inst = Instance("background", t.class_name, t.box, 0.0, 0.0, uuid=f"gt-{t.id}")
            out[inst.uuid] = inst
    return out


def _background(truth: Truth, background: str) -> tuple[list[Stage], World, str]:
    if background not in BACKGROUND_SOURCES:
        raise ConfigError(f"background {background!r}; expected one of {', '.join(BACKGROUND_SOURCES)}")
    if background == "truth":
        return [], World(background=_truth_background(truth)), "ground-truth boxes"
    try:
        stage = make_stage("background")
    except ConfigError:
        if background == "stage":
            raise
        return [], World(background=_truth_background(truth)), "ground-truth boxes (no background stage)"
    return [stage], World(), "hiper background stage"


def _both_ways_ids(truth: Truth) -> dict[str, set[int]]:
    """Per ``FOUND_BOTH_WAYS`` class, the ids of its truth instances."""
    out: dict[str, set[int]] = {}
    for i, t in truth.instances.items():
        if t.class_name in FOUND_BOTH_WAYS:
            out.setdefault(t.class_name, set()).add(i)
    return out


def _frame_truth(
    frame: Frame, truth: Truth, observations: list[Observation], foreground_ids: set[int],
    both_ways: dict[str, set[int]], step: int,
) -> tuple[dict[str, int | None], dict[str, float], dict[str, float]]:
    """Truth id per observation (majority of its pixel sample among the foreground ids, and
    for a ``FOUND_BOTH_WAYS`` class the ids ``both_ways`` gives it), and for the foreground ids
    its visible-centre error in 3D and horizontally."""
    rgb_rel = frame.source.split(" + ")[0] if frame.source else ""
    ids_img = truth.load_instance_ids(rgb_rel)
    ids: dict[str, int | None] = {}
    errors: dict[str, float] = {}
    errors_xy: dict[str, float] = {}
    visible_centres: dict[int, NDArray[np.float64] | None] = {}
    cam = frame.camera
    for obs in observations:
        uv = np.asarray(obs.data.get("pixels_uv", []), dtype=np.int64).reshape(-1, 2)
        if len(uv) == 0:
            ids[obs.uuid] = None
            continue
        hits = ids_img[np.clip(uv[:, 1], 0, cam.height - 1), np.clip(uv[:, 0], 0, cam.width - 1)]
        eligible = foreground_ids | both_ways.get(obs.class_name, set())
        counts = Counter(int(h) for h in hits if int(h) in eligible)
        best = counts.most_common(1)
        gid = best[0][0] if best and best[0][1] * 2 >= len(hits) else None
        ids[obs.uuid] = gid
        if gid is None or gid not in foreground_ids:
            continue  # a table's centre is its top's, which the background maps: no localisation
        if gid not in visible_centres:
            off = step // 2  # the stage's sampling grid
            sub_ids = ids_img[off::step, off::step]
            sub_depth = frame.depth_m[off::step, off::step]
            vs, us = np.nonzero((sub_ids == gid) & (sub_depth > 0))
            if len(us) == 0:
                visible_centres[gid] = None
            else:
                z = sub_depth[vs, us].astype(np.float64)
                u, v = us * step + off, vs * step + off
                p = np.stack([(u - cam.cx) * z / cam.fx, (v - cam.cy) * z / cam.fy, z], axis=1)
                p_map = p @ frame.T_map_cam[:3, :3].T + frame.T_map_cam[:3, 3]
                centre = p_map.mean(axis=0)  # the same centre the stage computes for a blob
                centre[2] = (p_map[:, 2].min() + p_map[:, 2].max()) / 2.0
                visible_centres[gid] = centre
        centre = visible_centres[gid]
        if centre is not None and "center_map" in obs.data:
            diff = np.asarray(obs.data["center_map"]) - centre
            errors[obs.uuid] = float(np.linalg.norm(diff))
            errors_xy[obs.uuid] = float(np.linalg.norm(diff[:2]))
    return ids, errors, errors_xy


def run_foreground(
    log_path: Path, truth: Truth, options: dict[str, Any], max_frames: int | None, background: str,
    priors: Sequence[Analysis] = (),
) -> ForegroundRun:
    """The background (``background``: see ``evaluate_foreground``) and foreground stages over
    the log in memory, with ``priors`` (learned features) in the world; then every observation
    is given its truth id and visible-centre error in a second pass, off the clock."""
    from hiper_cli.perceive.logs import open_log

    stages, world, source = _background(truth, background)
    world.analyses = list(priors)  # learned features the foreground stage reads
    foreground = make_stage("foreground", log_path=log_path, **options)
    stages.append(foreground)
    reader = open_log(log_path)
    run = ForegroundRun(world=world, background_source=source)
    fg_ids = {i for i, t in truth.instances.items() if t.layer == "foreground"}
    both_ways = _both_ways_ids(truth)
    step = ForegroundConfig.from_options(**options).pixel_step
    frame_index = itertools.count()

    by_frame: dict[int, list[Observation]] = {}

    def on_frame(frame: Frame | None, result: FrameResult) -> None:
        k = next(frame_index)
        for obs in result.observations:
            run.observations[obs.uuid] = obs
            run.obs_frame[obs.uuid] = k
        if frame is not None:
            by_frame[k] = result.observations
            run.foreground_times_s.append(result.timings_s.get("foreground_s", 0.0))
            run.points.append(result.timings_s.get("foreground_points", 0.0))
            after = result.timings_s.get("foreground_points_after_background", 0.0)
            run.points_after_background.append(after)

    frames = itertools.islice(iter(reader), max_frames) if max_frames else iter(reader)
    start = time.perf_counter()
    world, stats = run_stages(prefetch(frames), stages, world, on_frame)
    run.wall_s = time.perf_counter() - start
    # Scored in a second pass over the log, after the clock stopped: scoring inside the run
    # would compete with the detector thread for the CPU and cloud the frames per second.
    again = open_log(log_path)
    for k, frame in enumerate(itertools.islice(iter(again), stats.frames)):
        if by_frame.get(k):
            ids, errors, errors_xy = _frame_truth(frame, truth, by_frame[k], fg_ids, both_ways, step)
            run.obs_truth_id.update(ids)
            run.obs_visible_error_m.update(errors)
            run.obs_visible_error_xy_m.update(errors_xy)
    run.world, run.frames = world, stats.frames
    return run


def _mean_std(values: list[float] | NDArray[np.float64]) -> list[float | None]:
    arr = np.asarray(values, dtype=np.float64)
    if arr.size == 0:
        return [None, None]
    return [float(arr.mean()), float(arr.std())]


def _instance_truth(run: ForegroundRun, instances: list[Instance]) -> dict[str, int | None]:
    """Each instance's true object: the majority truth id of its observations."""
    inst_truth: dict[str, int | None] = {}
    for inst in instances:
        votes = Counter(run.obs_truth_id.get(u) for u in inst.observation_uuids)
        votes.pop(None, None)
        inst_truth[inst.uuid] = votes.most_common(1)[0][0] if votes else None
    return inst_truth


def _classification(
    instances: list[Instance], inst_truth: dict[str, int | None], truth: Truth
) -> tuple[dict[str, dict[str, int]], int]:
    """TP/FP per predicted class (``unknown`` left out) and the number of unknown instances."""
    per_class: dict[str, dict[str, int]] = {}
    unknown = 0
    for inst in instances:
        if inst.class_name == "unknown":
            unknown += 1
            continue
        gid = inst_truth[inst.uuid]
        ok = gid is not None and truth.instances[gid].class_name == inst.class_name
        counts = per_class.setdefault(inst.class_name, {"tp": 0, "fp": 0})
        counts["tp" if ok else "fp"] += 1
    return per_class, unknown


def _centre_errors(instances: list[Instance], inst_truth: dict[str, int | None], truth: Truth) -> list[float]:
    """Box-centre errors in metres: along the true path for walkers, at the box for the rest."""
    centre_err: list[float] = []
    for inst in instances:
        gid = inst_truth[inst.uuid]
        if gid is None:
            continue
        t = truth.instances[gid]
        if t.state == "dynamic" and gid in truth.tracks:
            path = TrackTrajectory.from_rows(inst.data.get("trajectory"))
            for stamp_s, position in zip(path.stamps_s, path.position_map_m, strict=True):
                p = truth.position_at(gid, float(stamp_s))
                if p is not None:
                    centre_err.append(float(np.linalg.norm(position - p)))
        else:
            centre_err.append(float(np.linalg.norm(inst.box.center_m - t.box.center_m)))
    return centre_err


def _people_speeds(
    instances: list[Instance], inst_truth: dict[str, int | None], truth: Truth, dynamic_speed_mps: float
) -> tuple[NDArray[np.float64], list[float], list[float]]:
    """All person speeds, and ours beside the truth's while a matched walker truly moves."""
    speeds: list[float] = []
    moving_ours: list[float] = []
    moving_truth: list[float] = []
    for inst in instances:
        if inst.class_name != "person":
            continue
        path = TrackTrajectory.from_rows(inst.data.get("trajectory"))
        sp = path.speed_xy_mps
        stamps = path.stamps_s
        speeds.extend(sp.tolist())
        gid = inst_truth[inst.uuid]
        if gid is None or gid not in truth.tracks:
            continue
        trk = truth.tracks[gid]
        true_vx = np.interp(stamps, trk[:, 0], trk[:, 4])
        true_sp = np.hypot(true_vx, np.interp(stamps, trk[:, 0], trk[:, 5]))
        inside = (stamps >= trk[0, 0]) & (stamps <= trk[-1, 0]) & (true_sp > dynamic_speed_mps)
        moving_ours.extend(sp[inside].tolist())
        moving_truth.extend(true_sp[inside].tolist())
    return np.asarray(speeds, dtype=np.float64), moving_ours, moving_truth


def _identity_switches(run: ForegroundRun, instances: list[Instance]) -> tuple[int, int]:
    """Identity switches and the truth objects seen: per frame and truth object, the instance
    of its largest observation; a switch is a change of that instance between frames."""
    best: dict[tuple[int, int], tuple[int, str]] = {}
    for inst in instances:
        for u in inst.observation_uuids:
            gid = run.obs_truth_id.get(u)
            if gid is None:
                continue
            key = (gid, run.obs_frame.get(u, 0))
            size = int(run.observations[u].data.get("num_points", 0)) if u in run.observations else 0
            if key not in best or size > best[key][0]:
                best[key] = (size, inst.uuid)
    by_truth: dict[int, list[tuple[int, str]]] = {}
    for (gid, k), (_, inst_uuid) in best.items():
        by_truth.setdefault(gid, []).append((k, inst_uuid))
    switches = 0
    for seq in by_truth.values():
        seq.sort()
        switches += sum(1 for a, b in itertools.pairwise(seq) if a[1] != b[1])
    return switches, len(by_truth)


def score_run(run: ForegroundRun, truth: Truth, dynamic_speed_mps: float) -> dict[str, Any]:
    """Table III figures of a run (see the module docstring); a person faster than
    ``dynamic_speed_mps`` counts as moving."""
    instances = list(run.world.foreground.values())
    inst_truth = _instance_truth(run, instances)
    per_class, unknown = _classification(instances, inst_truth, truth)
    tp = sum(r["tp"] for r in per_class.values())
    fp = sum(r["fp"] for r in per_class.values())
    visible_err = list(run.obs_visible_error_m.values())
    visible_err_xy = list(run.obs_visible_error_xy_m.values())
    classified_err = [
        e for u, e in run.obs_visible_error_m.items() if run.observations[u].class_name != "unknown"
    ]
    centre_err = _centre_errors(instances, inst_truth, truth)
    sp_arr, moving_ours, moving_truth = _people_speeds(instances, inst_truth, truth, dynamic_speed_mps)
    switches, truth_seen = _identity_switches(run, instances)
    times = run.foreground_times_s

    return {
        "frames": run.frames,
        "detect_time_s": _mean_std(times),
        "frames_per_s": run.frames_per_s,
        "foreground_frames_per_s": len(times) / sum(times) if times and sum(times) > 0 else 0.0,
        "points_mean": float(np.mean(run.points)) if run.points else 0.0,
        "points_after_background_mean": float(np.mean(run.points_after_background)) if run.points else 0.0,
        "classification": per_class,
        "tp": tp,
        "fp": fp,
        "fp_share": fp / (tp + fp) if tp + fp else None,
        "unknown_instances": unknown,
        "sum_i": len(instances),
        "sum_o": len(run.observations),
        "localisation_classified_m": _mean_std(classified_err),
        "localisation_visible_m": _mean_std(visible_err),
        "localisation_visible_median_m": float(np.median(visible_err)) if visible_err else None,
        "localisation_visible_xy_m": _mean_std(visible_err_xy),
        "localisation_visible_xy_median_m": float(np.median(visible_err_xy)) if visible_err_xy else None,
        "localisation_box_centre_m": _mean_std(centre_err),
        "people_dynamic_ratio": float(np.mean(sp_arr > dynamic_speed_mps)) if sp_arr.size else None,
        "people_speed_mps": _mean_std(sp_arr),
        "people_speed_ci_mps": (
            [float(np.percentile(sp_arr, 2.5)), float(np.percentile(sp_arr, 97.5))] if sp_arr.size else None
        ),
        "moving_people_speed_mps": _mean_std(moving_ours),
        "moving_people_true_speed_mps": _mean_std(moving_truth),
        "moving_people_speed_error_mps": (
            float(np.mean(moving_ours) - np.mean(moving_truth)) if moving_ours else None
        ),
        "identity_switches": switches,
        "truth_instances_seen": truth_seen,
    }


@dataclass(frozen=True)
class ForegroundReport:
    """Our Table III on one log (``to_dict`` is the ``--json`` form, with the paper's table).

    ``ours``: the scores (``score_run``: counts, times, localisation, people's speeds, identity
    switches); ``ablation``: the same run without background filtering (C4), when it ran.
    """

    log: str
    world: str
    seed: int
    detector: str
    background_filter: bool
    background_source: str
    classes: tuple[str, ...]
    exclude_classes: tuple[str, ...]
    ours: dict[str, Any]
    ablation: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "log": self.log, "world": self.world, "seed": self.seed, "detector": self.detector,
            "background_filter": self.background_filter, "background_source": self.background_source,
            "classes": list(self.classes), "exclude_classes": list(self.exclude_classes), "ours": self.ours,
            "paper": PAPER_TABLE_III, "true_people_speed_mps": TRUE_PEOPLE_SPEED_MPS,
        }
        if self.ablation is not None:
            out["ablation"] = self.ablation
        return out


def parse_settings(settings: Sequence[str], *, classes: str | None = None,
                   exclude_classes: str | None = None) -> dict[str, Any]:
    """Foreground options from ``KEY=VALUE`` text (values read as JSON when they parse);
    ``classes`` / ``exclude_classes`` (dedicated flags) win over the same keys."""
    out: dict[str, Any] = {}
    for item in settings:
        key, sep, raw = item.partition("=")
        if not sep or not key:
            raise ConfigError(f"--set {item!r}: expected KEY=VALUE, e.g. --set pixel_step=2")
        try:
            out[key.strip()] = json.loads(raw)
        except json.JSONDecodeError:
            out[key.strip()] = raw
    for key, value in (("classes", classes), ("exclude_classes", exclude_classes)):
        if value is not None:
            out[key] = value
    return out


@dataclass(frozen=True)
class PerceptionScore:
    """A perception run kept for what a caller reads from it (its world, each observation's
    truth id) and its ``Evaluation``."""

    run: ForegroundRun
    evaluation: Evaluation


def perceive_and_score(
    log_path: str | Path,
    *,
    background: str = "auto",
    max_frames: int | None = None,
    priors: Sequence[Analysis] = (),
    truth: Truth | None = None,
    **options: Any,
) -> PerceptionScore:
    """Perceive ``log_path`` (a log with ``gt/``) in memory and score the run per observation
    against its truth (Table III). ``options`` go to the foreground stage (``detector`` and the
    fields of ``ForegroundConfig``); ``priors``: learned features fed back; ``truth``: the
    log's, when the caller has read it already."""
    root = Path(log_path)
    truth = load_truth(root) if truth is None else truth
    dynamic_speed_mps = ForegroundConfig.from_options(**options).dynamic_speed_mps
    run = run_foreground(root, truth, options, max_frames, background, priors)
    figures = score_run(run, truth, dynamic_speed_mps)
    return PerceptionScore(run, Evaluation.of_perception(str(root), truth.world, figures))


def evaluate_foreground(
    log_path: str | Path,
    *,
    detector: str = "truth",
    background_filter: bool = True,
    ablation: bool = True,
    max_frames: int | None = None,
    background: str = "auto",
    **options: Any,
) -> ForegroundReport:
    """Table III of the paper on ``log_path`` (a ``hiper sim`` log); see the module docstring.

    ``background``: ``stage`` runs hiper's background stage, ``truth`` uses the ground-truth
    background boxes, ``auto`` the stage when this version has one. ``options`` go to the
    foreground stage (fields of ``ForegroundConfig``).
    """
    root = Path(log_path)
    truth = load_truth(root)
    opts = {"detector": detector, "background_filter": background_filter, **options}
    fg_config = ForegroundConfig.from_options(**opts)
    main = perceive_and_score(root, background=background, max_frames=max_frames, truth=truth, **opts)
    ours = main.evaluation.figures
    c4: dict[str, Any] | None = None
    if ablation and background_filter:
        off = {**opts, "background_filter": False}
        scored = perceive_and_score(root, background=background, max_frames=max_frames, truth=truth,
                                    **off).evaluation.figures
        base = ours["detect_time_s"][0]
        slow = scored["detect_time_s"][0]
        c4 = {
            "detect_time_s": scored["detect_time_s"],
            "frames_per_s": scored["frames_per_s"],
            "fp_share": scored["fp_share"],
            "sum_i": scored["sum_i"],
            "points_after_background_mean": scored["points_after_background_mean"],
            "latency_increase": (slow / base - 1.0) if base and slow is not None else None,
        }
    return ForegroundReport(
        log=str(root), world=truth.world, seed=truth.seed, detector=detector,
        background_filter=background_filter, background_source=main.run.background_source,
        classes=tuple(fg_config.classes), exclude_classes=tuple(fg_config.exclude_classes), ours=ours,
        ablation=c4,
    )

