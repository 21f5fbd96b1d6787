"""Feature learning (paper VI-A): the Object Dynamic Score, size and altitude of each class.

Speeds are the horizontal speeds |(vx, vy)| of the trajectory rows (the tracker's filtered
velocity). The rows of a static instance stand (its state: the tracker found it never moved;
its filter drifts as more of it comes into view, a table seen end first and then whole, and
the drift is no motion); σ of the folded-normal noise of the other rows' standing phases is
estimated per class, and those above ``noise_sigmas · σ`` (paper: 2σ) are the dynamic
portion D. Size (box volume) and altitude (box bottom above the floor) are per instance: a
track's box is the object's extent over all its sightings, where one observation sees only
part of it. Confidence intervals of the means
are percentile bootstraps; the speed's resamples whole tracks. Everything is computed from
column reads of the knowledge base (``graph.columns``), never from a document per row.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.analyze.stats import bootstrap_mean_ci, folded_normal_sigma
from hiper_cli.analyze.window import TimeWindow
from hiper_cli.errors import ConfigError
from hiper_cli.graph.columns import TrajectoryColumns
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.learned import AltitudeFeature, ObjectDynamics, SizeFeature
from hiper_cli.model import Analysis

__all__ = [
    "ClassFeatures",
    "FeatureConfig",
    "FeatureReport",
    "check_classes",
    "compute_features",
    "features_of_tracks",
    "learn_features",
    "store_features",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class FeatureConfig:
    """Paper constants as named fields: the 2σ noise threshold and 95 % intervals."""

    noise_sigmas: float = 2.0
    """A speed above this many σ of the stationary noise is motion (paper: 2σ, 95.45 %)."""
    level: float = 0.95
    """Confidence level of the bootstrap intervals and width of the value ranges."""
    bootstrap_samples: int = 1000
    seed: int = 0
    min_sigma_mps: float = 0.005
    """Floor of the noise σ (a track that never moves has exact zeros)."""
    max_sigma_mps: float = 0.15
    """Cap of the noise σ: a standing object's tracked velocity jitters by centimetres per
    second; a class that always moves must not have its walking taken for noise."""
    min_instances: int = 1
    """Classes with fewer instances in the window are left out."""
    moving_class_ratio: float = 0.5
    """A class with at least this dynamic share (people) learns its size and altitude from its
    tracks that moved (``moving_track_share`` of their rows dynamic): a person on a poster or a
    TV screen never walks, so the detector's false positives do not widen the ranges that are
    meant to reject them."""
    moving_track_share: float = 0.5

    def __post_init__(self) -> None:
        if self.noise_sigmas <= 0 or not 0 < self.level < 1 or self.bootstrap_samples < 10:
            raise ConfigError(
                "features: need noise_sigmas > 0, 0 < level < 1 and bootstrap_samples >= 10, got "
                f"{self.noise_sigmas}, {self.level}, {self.bootstrap_samples}"
            )


@dataclass(frozen=True)
class ClassFeatures:
    """The learned features of one class in one window, with the samples behind them."""

    class_name: str
    ods: ObjectDynamics
    size: SizeFeature | None
    altitude: AltitudeFeature | None
    speeds_mps: FloatArray = field(repr=False)
    volumes_m3: FloatArray = field(repr=False)
    altitudes_m: FloatArray = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "class": self.class_name,
            "ods": self.ods.to_values(),
            "size": None if self.size is None else self.size.to_values(),
            "altitude": None if self.altitude is None else self.altitude.to_values(),
        }

    def analyses(self, t_start_s: float, t_end_s: float, created_s: float) -> list[Analysis]:
        parts = [self.ods, self.size, self.altitude]
        return [p.to_analysis(self.class_name, t_start_s, t_end_s, created_s) for p in parts if p is not None]


@dataclass(frozen=True)
class FeatureReport:
    """Features of every class found in the window; ``t_start_s``/``t_end_s`` the data's span."""

    window: TimeWindow
    t_start_s: float
    t_end_s: float
    floor_z_m: float
    classes: list[ClassFeatures]
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "window": self.window.to_dict(),
            "t_start_s": self.t_start_s,
            "t_end_s": self.t_end_s,
            "floor_z_m": self.floor_z_m,
            "classes": [c.to_dict() for c in self.classes],
            "seconds": round(self.seconds, 4),
        }

    def analyses(self) -> list[Analysis]:
        now = time.time()
        return [a for c in self.classes for a in c.analyses(self.t_start_s, self.t_end_s, now)]


def _value_feature(values: FloatArray, config: FeatureConfig) -> tuple[float, float, float, float, float]:
    mean, lo, hi = bootstrap_mean_ci(
        values, level=config.level, samples=config.bootstrap_samples, seed=config.seed
    )
    alpha = 100.0 * (1.0 - config.level) / 2.0
    r_lo, r_hi = np.percentile(values, [alpha, 100.0 - alpha])
    return mean, lo, hi, float(r_lo), float(r_hi)


def object_dynamics(
    speeds_mps: FloatArray, track: NDArray[np.int64], config: FeatureConfig,
    still: NDArray[np.bool_] | None = None,
) -> ObjectDynamics:
    """The ODS of one class from its rows' speeds and the track of each row; ``still`` rows (of
    static instances) stand, and the noise σ is that of the other rows when there are any."""
    still = np.zeros(speeds_mps.shape, dtype=bool) if still is None else still
    noisy = speeds_mps[~still] if np.any(~still) else speeds_mps
    sigma = folded_normal_sigma(noisy, config.noise_sigmas, config.min_sigma_mps, config.max_sigma_mps)
    threshold = config.noise_sigmas * sigma
    dynamic = (speeds_mps > threshold) & ~still
    d = speeds_mps[dynamic]
    mean = lo = hi = cl = cu = None
    if d.size:
        m, a, b = bootstrap_mean_ci(
            d, track[dynamic], level=config.level, samples=config.bootstrap_samples, seed=config.seed
        )
        alpha = 100.0 * (1.0 - config.level) / 2.0
        p_lo, p_hi = np.percentile(d, [alpha, 100.0 - alpha])
        mean, lo, hi, cl, cu = m, a, b, float(p_lo), float(p_hi)
    return ObjectDynamics(
        mean_mps=mean,
        mean_lo_mps=lo,
        mean_hi_mps=hi,
        cl_mps=cl,
        cu_mps=cu,
        ratio=float(dynamic.mean()) if speeds_mps.size else 0.0,
        sigma_mps=sigma,
        threshold_mps=threshold,
        rows=int(speeds_mps.size),
        dynamic_rows=int(d.size),
        instances=int(np.unique(track).size),
    )


def features_of_tracks(
    tracks: TrajectoryColumns, window: TimeWindow, floor_z_m: float = 0.0, config: FeatureConfig | None = None
) -> list[ClassFeatures]:
    """Per class: ODS, size and altitude of the tracks' rows that lie in ``window``."""
    config = config or FeatureConfig()
    rows, track = tracks.rows, tracks.track
    if window != TimeWindow():
        keep = window.mask(rows[:, 0])
        rows, track = rows[keep], track[keep]
    inst = tracks.instances
    names, codes = np.unique(np.asarray(inst.class_names, dtype=str), return_inverse=True)
    row_code = codes[track] if track.size else np.zeros(0, dtype=np.int64)
    speeds = np.hypot(rows[:, 4], rows[:, 5])
    still = inst.static[track]
    out: list[ClassFeatures] = []
    for code, name in enumerate(names.tolist()):
        sel = row_code == code
        seen = np.unique(track[sel])
        if seen.size < config.min_instances:
            continue
        ods = object_dynamics(speeds[sel], track[sel], config, still[sel])
        n_rows = np.bincount(track[sel], minlength=len(inst.uuids)).astype(np.float64)
        z_sum = np.bincount(track[sel], weights=rows[sel, 3], minlength=len(inst.uuids))
        if ods.ratio >= config.moving_class_ratio:
            fast = speeds[sel] > ods.threshold_mps
            moved = np.bincount(track[sel], weights=fast, minlength=len(inst.uuids))
            moving = seen[moved[seen] >= config.moving_track_share * n_rows[seen]]
            seen = moving if moving.size else seen
        volumes = np.prod(inst.extent_m[seen], axis=1)
        # the box bottom: the track's mean centre height (the last position alone is one noisy row)
        altitudes = z_sum[seen] / n_rows[seen] - inst.half_aabb_m[seen, 2] - floor_z_m
        size = altitude = None
        if seen.size:
            size = SizeFeature(*_value_feature(volumes, config), instances=int(seen.size))
            altitude = AltitudeFeature(*_value_feature(altitudes, config), instances=int(seen.size))
        out.append(ClassFeatures(name, ods, size, altitude, speeds[sel], volumes, altitudes))
    return out


def floor_height_m(kb: KnowledgeBase) -> float:
    """The height of the floor in the map frame: the top of the largest floor instance (0 when
    the knowledge base has none)."""
    floors = kb.instance_columns("floor", layer="background")
    if not floors.uuids:
        return 0.0
    biggest = int(np.argmax(floors.half_aabb_m[:, 0] * floors.half_aabb_m[:, 1]))
    return float(floors.center_map_m[biggest, 2] + floors.half_aabb_m[biggest, 2])


def compute_features(
    kb: KnowledgeBase,
    class_names: Sequence[str] | None = None,
    window: TimeWindow | None = None,
    config: FeatureConfig | None = None,
) -> FeatureReport:
    """The features of ``class_names`` (default: every foreground class) in ``window``."""
    t_start = time.perf_counter()
    window = window or TimeWindow()
    config = config or FeatureConfig()
    wanted = list(class_names) if class_names else [None]
    classes: list[ClassFeatures] = []
    lo_s, hi_s = math.inf, -math.inf
    floor_z = floor_height_m(kb)
    for name in wanted:
        tracks = kb.trajectory_columns(name, window.t_start_s, window.t_end_s)
        stamps = tracks.rows[:, 0]
        if window.daily_s is not None:
            stamps = stamps[window.mask(stamps)]
        if stamps.size:
            lo_s, hi_s = min(lo_s, float(stamps.min())), max(hi_s, float(stamps.max()))
        classes.extend(features_of_tracks(tracks, window, floor_z, config))
    if not math.isfinite(lo_s):
        lo_s = hi_s = 0.0
    return FeatureReport(window, lo_s, hi_s, floor_z, classes, time.perf_counter() - t_start)


def store_features(kb: KnowledgeBase, report: FeatureReport) -> list[Analysis]:
    """Write the report's analyses into the knowledge base's map layer; returns them. (The
    scene graph follows on the next sync: ``kb.close()`` does one.)"""
    analyses = report.analyses()
    kb.put_analyses(analyses)
    return analyses


def check_classes(kb: KnowledgeBase, class_names: Sequence[str]) -> None:
    """A ``ConfigError`` naming the classes the knowledge base knows when one asked is not there."""
    known = kb.foreground_classes()
    missing = [c for c in class_names if c not in known]
    if missing:
        have = ", ".join(known) if known else "none (run 'hiper perceive LOG' first)"
        raise ConfigError(
            f"class {missing[0]!r}: no foreground instances of it in {kb.location}; classes: {have}"
        )


def learn_features(
    kb: KnowledgeBase,
    class_names: Sequence[str] | None = None,
    window: TimeWindow | None = None,
    config: FeatureConfig | None = None,
    *,
    store: bool = True,
) -> tuple[FeatureReport, list[Analysis]]:
    """``hiper analyze features``: check the classes, compute their features and (``store``)
    write them as analyses; returns the report and the analyses written."""
    if class_names:
        check_classes(kb, class_names)
    report = compute_features(kb, class_names, window, config)
    return report, (store_features(kb, report) if store else [])
