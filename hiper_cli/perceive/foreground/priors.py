"""Classify: the learned priors of a class (``hiper analyze features``) as the stage reads them.

The knowledge base's ``ods``, ``size`` and ``altitude`` analyses, each a class's feature learned
from its instances, become the tracker's gate and motion noise for the class (``class_prior``)
and a test of whether a named blob can be of the class at all (``fits``). A feature is a prior
only when learned from ``PRIOR_MIN_INSTANCES`` instances.
"""

from __future__ import annotations

import numpy as np

from hiper_cli.errors import DataError
from hiper_cli.learned import (
    FEATURE_KINDS,
    KIND_ALTITUDE,
    KIND_ODS,
    KIND_SIZE,
    AltitudeFeature,
    ObjectDynamics,
    SizeFeature,
    feature_from_analysis,
)
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.perceive.foreground.track import ClassPrior
from hiper_cli.perceive.foreground.whole import inside_image, occluded
from hiper_cli.perceive.stage import World
from hiper_cli.types import Frame

__all__ = ["LearnedPriors"]

PRIOR_TOLERANCE = 0.5
"""Size / altitude priors reject a class when a blob is outside [lo·(1-t), hi·(1+t)]."""
PRIOR_MIN_INSTANCES = 3
"""A class's learned feature is a prior only when learned from this many instances: the range
of one TV's altitude is a point, and the views of the next TV, stand in or out, are not."""
MIN_ALTITUDE_SPAN_M = 0.2  # the altitude prior's slack grows with at least this span

Feature = ObjectDynamics | SizeFeature | AltitudeFeature


class LearnedPriors:
    """The learned features of the world's analyses, refreshed when analyses are added."""

    def __init__(self, config: ForegroundConfig) -> None:
        self.config = config
        self._features: dict[tuple[str, str], Feature] = {}
        self._analyses_seen = -1

    def refresh(self, world: World) -> None:
        if len(world.analyses) == self._analyses_seen:
            return
        self._analyses_seen = len(world.analyses)
        self._features = {}
        for a in sorted(world.analyses, key=lambda a: a.created_s):
            if a.kind in FEATURE_KINDS:
                try:
                    self._features[(a.kind, a.class_name)] = feature_from_analysis(a)
                except DataError:  # written by an older hiper: no prior rather than no run
                    continue

    def _feature(self, kind: str, class_name: str) -> Feature | None:
        """The learned feature of a class, when learned from ``PRIOR_MIN_INSTANCES`` instances."""
        found = self._features.get((kind, class_name))
        return found if found is not None and found.instances >= PRIOR_MIN_INSTANCES else None

    def class_prior(self, class_name: str) -> ClassPrior:
        """The tracker's gate bound and motion noise for ``class_name`` (``ods``)."""
        cfg = self.config
        ods = self._feature(KIND_ODS, class_name)
        if not isinstance(ods, ObjectDynamics) or not cfg.use_learned_priors:
            return ClassPrior()
        return ClassPrior(
            cu_mps=ods.cu_mps if cfg.learned_gates else None,
            # a class seen only standing taught no motion: its σ is the drift of its own filter
            sigma_mps=ods.sigma_mps if cfg.learned_motion_noise and ods.dynamic_rows else None,
        )

    def fits(self, class_name: str, blob: Blob, frame: Frame) -> bool:
        """False when the learned size / altitude of ``class_name`` rule the blob out.

        The priors are learned from instances, each the extent of all its views; one view shows
        at most the whole object. A blob larger than the class's range, or whose bottom lies
        below it, is something else. A smaller one is no evidence: a partial view, or samples a
        pixel step apart (a bottle at 3 m is a column of points). A walker's instance box is a
        running mean of its views, partial ones included, so its size range bounds no view. A
        bottom above the range rules the class out only when the blob is seen whole (inside the
        image, nothing nearer cuts it): a person close by, legs below the image, keeps its class."""
        cfg = self.config
        if not cfg.use_learned_priors:
            return True
        tol = PRIOR_TOLERANCE
        size = self._feature(KIND_SIZE, class_name)
        bounded = cfg.learned_size and class_name not in cfg.walker_classes  # walkers: a mean box
        volume_m3 = float(np.prod(blob.extent_map_m))
        if bounded and isinstance(size, SizeFeature) and volume_m3 > size.hi_m3 * (1 + tol):
            return False
        alt = self._feature(KIND_ALTITUDE, class_name)
        if cfg.learned_altitude and isinstance(alt, AltitudeFeature):
            slack = tol * max(alt.hi_m - alt.lo_m, MIN_ALTITUDE_SPAN_M)
            bottom = float(blob.center_map_m[2] - blob.extent_map_m[2] / 2.0)
            if bottom < alt.lo_m - slack:
                return False
            if bottom > alt.hi_m + slack:  # seen whole, its bottom is the object's
                step = cfg.pixel_step
                return not inside_image(blob, step, frame.camera) or occluded(
                    blob, frame.depth_m, frame.camera, frame.T_map_cam, step
                )
        return True
