"""A tracked object and what the tracker is told: a ``Track`` (its filter, its blobs' boxes, its
class votes, its trajectory), a ``Measurement`` (one observed blob) and a ``ClassPrior``.

The data the tracker's parts share (``tracking.py`` runs them; ``class_vote``, ``moving``,
``same_object``, ``stitch`` and ``smoother`` read and change a ``Track``); it
imports none of them but the class vote, so that the parts import it, not the tracker.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.class_vote import search_class, winner
from hiper_cli.perceive.foreground.motion import MotionModel
from hiper_cli.perceive.foreground.seen_box import SeenBox

__all__ = ["ClassPrior", "Measurement", "NamedBlob", "Track"]

FloatArray = NDArray[np.float64]


class NamedBlob(NamedTuple):
    """The blob a detection named in one frame: which detection, and the blob's map-frame box."""

    detection: int
    lower_m: NDArray[np.float64]
    upper_m: NDArray[np.float64]
    xyxy_px: NDArray[np.float64] | None = None  # the detection's image box


@dataclass(frozen=True)
class Measurement:
    """One observed blob for the tracker: centre and extent in the map frame."""

    center_map_m: FloatArray
    extent_map_m: FloatArray
    class_name: str
    score: float
    observation_uuid: str
    whole: bool | None = True
    """Seen whole: inside the image, compact and solid (``unknown_confirm_whole``); None: cannot
    tell, its base hidden behind something nearer (``whole.seen_whole``)."""
    appearance: FloatArray | None = None
    """Colour histogram of the blob (``appearance.histogram``), None when not computed."""
    standing: tuple[FloatArray, FloatArray] | None = None
    """(centre, extent) of the blob as a walker's box, from the floor to its top
    (``walker_from_floor``): what a walking track takes instead of the blob's own box."""
    bounds_map_m: tuple[FloatArray, FloatArray] | None = None
    """(lower, upper) corners of the blob's box, map frame (``SeenBox``); None: the box of
    ``center_map_m`` and ``extent_map_m``."""
    longest_m: float | None = None
    """The longest dimension of a named blob seen whole (``plausible.longest_m``): what the view
    shows of the object's size; None: cut by the image's border, hidden in part by something
    nearer (``whole.occluded``), of a class without a lower size bound, or not named."""
    detection_index: int | None = None
    """Which detection of its frame named the blob (None: none): two tracks named by different
    detections side by side in one frame are two objects (``same_object.seen_apart``)."""
    detection_xyxy_px: FloatArray | None = None
    """The image box (x0, y0, x1, y1; pixels) of the detection that named the blob."""
    viewpoint_map_m: FloatArray | None = None
    """The camera's position (map frame) when it saw the blob: which side of the object it saw
    (``amodal``)."""
    top_hidden: bool = False
    """The view did not show the object's top (``whole.top_hidden``; ``amodal``)."""
    bottom_hidden: bool = False
    """The view did not show where the object stands (``whole.bottom_hidden``; ``amodal``)."""
    full_view: bool = False
    """The view showed all of the blob, large enough to name (``whole.in_full_view``): one in
    which a detector named a class neither for the blob nor inside its box (``named_within``)
    counts against that class (``class_vote``)."""
    named_within: frozenset[str] = frozenset()
    """Classes of detections lying inside the blob's image box (``match.named_within``)."""
    closer_class: str | None = None
    """The class a keyframe's closer look gave the blob, ``unknown`` included, when it saw the blob
    whole (``keyframes.py``; None: no closer look): it counts in the closer looks' own vote
    (``class_vote``), never in the every-frame one."""
    cut_by_border: bool = False
    """The blob reaches the image's border (``whole.inside_image``): the view shows a part of its
    object, and its class vote counts ``class_vote.CUT_VIEW_WEIGHT``."""

    def corners(self) -> tuple[FloatArray, FloatArray]:
        if self.bounds_map_m is not None:
            return self.bounds_map_m
        half = self.extent_map_m / 2.0
        return self.center_map_m - half, self.center_map_m + half

    def for_walker(self) -> tuple[FloatArray, FloatArray]:
        """The (centre, extent) a walking track takes."""
        return self.standing if self.standing is not None else (self.center_map_m, self.extent_map_m)


@dataclass(frozen=True)
class ClassPrior:
    """Learned dynamics of a class (``ods`` analysis): upper speed bound and speed spread."""

    cu_mps: float | None = None
    sigma_mps: float | None = None


@dataclass
class Track:
    """One tracked object; becomes an ``Instance`` once confirmed."""

    uuid: str
    motion: MotionModel  # the state estimate (``ForegroundConfig.motion_model``)
    first_seen_s: float
    last_update_s: float
    last_time_s: float
    extent_m: FloatArray
    max_size_m: float = 0.0  # the largest blob seen (``_size_m``: footprint diagonal or height)
    hits: int = 1
    whole_stamps_s: list[float] = field(default_factory=list)  # of the whole observations
    unsure_views: int = 0  # observations that could not tell whether it was whole (``whole=None``)
    whole_footprint_m: FloatArray | None = None  # smoothed like ``extent_m``, whole views only
    unseen_in_view_s: float = 0.0
    confirmed: bool = False
    closed: bool = False
    # summed colour histograms of the observations a detection named a walker (``stitch``)
    appearance: FloatArray | None = None
    # its ``provisional_class``, hits and seen footprint (m²) when last offered to
    # ``find_target``; offered again when its hits double or its footprint grows
    # (``same_object.due``)
    stitch_class: str | None = None
    stitch_hits: int = 0
    stitch_area_m2: float = 0.0
    # a walker's standing boxes seen (``Measurement.standing``): tops and floor, map z
    standing_tops_m: list[float] = field(default_factory=list)
    floor_z_m: float | None = None
    # the boxes of its blobs: a static object's box (``object_box``)
    seen: SeenBox = field(default_factory=SeenBox)
    # stamp (rounded, ``same_object.STAMP_DECIMALS``) -> the detection that named its blob then
    named_at: dict[float, NamedBlob] = field(default_factory=dict)
    apart_from: set[str] = field(default_factory=set)  # tracks seen apart for good (``seen_apart``)
    velocity_initialised: bool = False
    first_center: FloatArray = field(default_factory=lambda: np.zeros(3))
    class_votes: dict[str, float] = field(default_factory=dict)
    class_counts: dict[str, int] = field(default_factory=dict)
    # per known class, the longest of its blobs seen inside the image (``Measurement.longest_m``)
    class_longest_m: dict[str, float] = field(default_factory=dict)
    # full views (``Measurement.full_view``) in all, and per known class those named it
    full_views: int = 0
    full_named: dict[str, int] = field(default_factory=dict)
    detected_classes: set[str] = field(default_factory=set)  # classes a detection gave it
    # the vote of the keyframes' closer looks alone (``Measurement.closer_class``)
    closer_counts: dict[str, int] = field(default_factory=dict)
    # the vote of the focused looks at it (``focus.py``, ``class_vote.record_focus``)
    focus_counts: dict[str, int] = field(default_factory=dict)
    refused_min_views: int = 0  # ``TrackerConfig.refused_min_views`` (0: off)
    min_class_observations: int = 1
    min_class_share: float = 0.0
    size_tolerance: float | None = None  # ``class_size_tolerance`` when ``class_sizes`` is on
    score_sum: float = 0.0
    observation_uuids: list[str] = field(default_factory=list)
    # one row per update: ``model.TRAJECTORY_COLUMNS`` (stamp, position, velocity; map frame)
    trajectory: list[list[float]] = field(default_factory=list)
    # per trajectory row not smoothed yet (the last ones, ``covariances_from`` on): posterior
    # covariance and the process noise (q, q_vertical) used
    covariances: list[FloatArray] = field(default_factory=list)
    noises: list[tuple[float, float]] = field(default_factory=list)
    # it was seen moving and went somewhere (``moving.note_travel``): a dynamic object; since
    # when it has been moving at every update (None: not moving)
    travelled: bool = False
    moving_since_s: float | None = None
    _class_name: str | None = field(default=None, repr=False)  # cache; ``class_vote`` clears it
    # ``moving.was_moving`` for the trajectory of this many rows (rows change only by being added)
    _moving: tuple[int, bool] | None = field(default=None, repr=False)

    @property
    def position(self) -> FloatArray:
        return np.asarray(self.motion.x[:3], dtype=np.float64)

    @property
    def velocity(self) -> FloatArray:
        return np.asarray(self.motion.x[3:], dtype=np.float64)

    @property
    def covariances_from(self) -> int:
        """The first trajectory row not smoothed yet: those before were smoothed when the track
        closed earlier (a walker lost, then resumed)."""
        return len(self.trajectory) - len(self.covariances)

    @property
    def class_name(self) -> str:
        """The class its observations voted for, with minimum evidence (``class_vote.winner``)."""
        if self._class_name is None:
            self._class_name = winner(self)
        return self._class_name

    @property
    def search_class(self) -> str:
        """The class that decides whether the track searches when lost (``search_classes``;
        ``class_vote.search_class``): a book display taken for a bed does not walk away."""
        return search_class(self)

    @property
    def confidence(self) -> float:
        return self.score_sum / max(self.hits, 1)
