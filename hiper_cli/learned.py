"""The typed contract of learned features: what an ``Analysis`` of kind ``ods``, ``size`` or
``altitude`` holds, and the speed of a trajectory.

``hiper_cli.analyze`` computes these features from the knowledge base and stores them as
analyses; the foreground stage (``hiper_cli.perceive``) reads them back as class priors. The
stage sits upstream of ``analyze`` (imports flow one way), so the contract lives here, beside
``model.py``, and both sides import it: the keys exist in one place only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any, ClassVar, TypeVar

import numpy as np

from hiper_cli.errors import DataError
from hiper_cli.model import Analysis

__all__ = [
    "FEATURE_KINDS",
    "KIND_ALTITUDE",
    "KIND_HEATMAP",
    "KIND_ODS",
    "KIND_SIZE",
    "AltitudeFeature",
    "ObjectDynamics",
    "SizeFeature",
    "feature_from_analysis",
    "path_speed_mps",
    "typical_speed_mps",
]

KIND_ODS = "ods"
KIND_SIZE = "size"
KIND_ALTITUDE = "altitude"
KIND_HEATMAP = "heatmap"
FEATURE_KINDS: tuple[str, ...] = (KIND_ODS, KIND_SIZE, KIND_ALTITUDE)

F = TypeVar("F", bound="_Feature")


@dataclass(frozen=True)
class _Feature:
    """Shared conversions: the fields are the ``Analysis.values`` keys, one to one."""

    kind: ClassVar[str]

    def to_values(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_values(cls: type[F], values: Mapping[str, Any]) -> F:
        """The feature stored in ``values``; a missing key is a ``DataError`` naming it."""
        kwargs: dict[str, Any] = {}
        for f in fields(cls):
            if f.name not in values:
                raise DataError(
                    f"{cls.kind} analysis: missing value {f.name!r} (has {sorted(values)}); "
                    "run 'hiper analyze features' again to rewrite it"
                )
            v = values[f.name]
            kwargs[f.name] = int(v) if f.type == "int" else (None if v is None else float(v))
        return cls(**kwargs)

    def to_analysis(self, class_name: str, t_start_s: float, t_end_s: float, created_s: float) -> Analysis:
        return Analysis(self.kind, class_name, t_start_s, t_end_s, self.to_values(), created_s)


@dataclass(frozen=True)
class ObjectDynamics(_Feature):
    """The Object Dynamic Score ODS = [μ_v, c_l, c_u, r] of a class (paper VI-A).

    ``sigma_mps``: σ of the folded-normal stationary noise; a speed above ``2σ``
    (``threshold_mps``) is motion. ``mean_mps`` (μ_v) is the mean speed of the dynamic portion,
    ``mean_lo_mps``/``mean_hi_mps`` its 95 % bootstrap confidence interval (tracks resampled);
    ``cl_mps``/``cu_mps`` the 2.5th/97.5th percentiles of the dynamic speeds (the class's speed
    range: the tracker gates at ``cu_mps · dt``); ``ratio`` the dynamic share of all rows.
    """

    kind: ClassVar[str] = KIND_ODS
    mean_mps: float | None
    mean_lo_mps: float | None
    mean_hi_mps: float | None
    cl_mps: float | None
    cu_mps: float | None
    ratio: float
    sigma_mps: float
    threshold_mps: float
    rows: int
    dynamic_rows: int
    instances: int


@dataclass(frozen=True)
class SizeFeature(_Feature):
    """Box volume of a class: mean with its 95 % bootstrap CI (``mean_lo_m3``/``mean_hi_m3``)
    and the 2.5th-97.5th percentile range (``lo_m3``/``hi_m3``) a new detection must fit."""

    kind: ClassVar[str] = KIND_SIZE
    mean_m3: float
    mean_lo_m3: float
    mean_hi_m3: float
    lo_m3: float
    hi_m3: float
    instances: int


@dataclass(frozen=True)
class AltitudeFeature(_Feature):
    """Height of the box bottom above the floor (z = 0 of the map): mean, its 95 % bootstrap
    CI and the 2.5th-97.5th percentile range (``lo_m``/``hi_m``)."""

    kind: ClassVar[str] = KIND_ALTITUDE
    mean_m: float
    mean_lo_m: float
    mean_hi_m: float
    lo_m: float
    hi_m: float
    instances: int


_BY_KIND: dict[str, type[_Feature]] = {c.kind: c for c in (ObjectDynamics, SizeFeature, AltitudeFeature)}


def feature_from_analysis(analysis: Analysis) -> ObjectDynamics | SizeFeature | AltitudeFeature:
    """The typed feature an ``ods``/``size``/``altitude`` analysis holds."""
    cls = _BY_KIND.get(analysis.kind)
    if cls is None:
        raise DataError(f"analysis {analysis.uuid}: kind {analysis.kind!r}, expected one of {FEATURE_KINDS}")
    return cls.from_values(analysis.values)  # type: ignore[return-value]


SPEED_WINDOW_S = 0.3
"""``path_speed_mps`` measures the path between positions at least this far apart in time: a
few centimetres of per-row jitter at 30 Hz would otherwise add up to tenths of a m/s, while a
walker's turn at an end point cuts at most a few centimetres of path."""
SPEED_MAX_GAP_S = 1.0
"""A gap between rows longer than this (the track unseen, then re-identified) splits the path:
neither its path nor its time counts (what happened in it is unknown; counted, a person picked
up again 10 s later read half their walking speed)."""


def path_speed_mps(rows: Sequence[Sequence[Any]] | np.ndarray) -> float | None:
    """Mean speed along trajectory rows [stamp_s, x, y, z, ...]: path length over duration,
    the path through positions ``SPEED_WINDOW_S`` apart (robust to jitter), gaps longer than
    ``SPEED_MAX_GAP_S`` left out. None for fewer than two rows, no elapsed time, or rows
    that are not numbers."""
    try:
        arr = np.asarray([r[:4] for r in rows], dtype=np.float64)
    except (TypeError, ValueError, IndexError):
        return None
    if arr.ndim != 2 or arr.shape[0] < 2 or arr.shape[1] != 4:
        return None
    if not float(arr[-1, 0] - arr[0, 0]) > 0:
        return None
    length_m = duration_s = 0.0
    breaks = np.flatnonzero(np.diff(arr[:, 0]) > SPEED_MAX_GAP_S) + 1
    for part in np.split(arr, breaks):  # the stretches the track was seen without a long gap
        keep = [0]
        for i in range(1, len(part)):
            if part[i, 0] - part[keep[-1], 0] >= SPEED_WINDOW_S:
                keep.append(i)
        if keep[-1] != len(part) - 1:
            keep.append(len(part) - 1)
        kept = part[keep]
        length_m += float(np.linalg.norm(np.diff(kept[:, 1:4], axis=0), axis=1).sum())
        duration_s += float(part[-1, 0] - part[0, 0])
    if not duration_s > 0:
        return None
    speed = length_m / duration_s
    return speed if math.isfinite(speed) else None


def typical_speed_mps(rows: Sequence[Sequence[Any]] | np.ndarray) -> float | None:
    """An instance's speed: the median of its rows' filtered speeds |v| (rows [stamp_s, x, y,
    z, vx, vy, vz]), or ``path_speed_mps`` for rows without velocities (or all of them 0). The
    median reads a walker's pace: a constant-velocity filter slows down at each reversal and
    cuts the end of the path (the path speed of people walking back and forth read 5-10 % low),
    and a static object's jitter stays near 0. None for no rows or rows that are not numbers."""
    try:
        arr = np.asarray([r[:7] for r in rows], dtype=np.float64)
    except (TypeError, ValueError, IndexError):
        return path_speed_mps(rows)
    if arr.ndim != 2 or arr.shape[0] < 2 or arr.shape[1] != 7 or not np.any(arr[:, 4:7]):
        return path_speed_mps(rows)  # no velocities (all zero: rows of a stage that has none)
    speed = float(np.median(np.linalg.norm(arr[:, 4:7], axis=1)))
    return speed if math.isfinite(speed) else None
