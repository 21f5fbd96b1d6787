"""Options of the foreground stage, grouped by concept: segment, associate, fuse, track, classify.

Frozen dataclasses, the paper's constants as defaults. The point-cloud parts build on each
other as the steps do: ``SamplingConfig`` (which depth pixels) < ``BackgroundFilterConfig``
(dropping points of background instances) < ``SegmentConfig`` (Algorithm 3) < ``RefineConfig``
(blobs refined with the detections). ``MatchConfig`` (Algorithm 4) and ``TrackerConfig``
(associate, fuse, track) stand alone; ``ForegroundConfig`` is all of them plus the detector's
options. Each module is typed to take only the part it reads, so mypy keeps the parts apart.
Options are flat names (``gate_m``) or dotted by concept (``associate.gate_m``, as in
``-o foreground.associate.gate_m=0.8``). A value nobody should tune is a named constant, with
its unit, beside the code that uses it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.foreground.classes import INDOOR_EXCLUDED

__all__ = [
    "BackgroundFilterConfig",
    "ForegroundConfig",
    "MatchConfig",
    "RefineConfig",
    "SamplingConfig",
    "SegmentConfig",
    "TrackerConfig",
]


def _as_tuples(config: object, names: tuple[str, ...]) -> None:
    """Store each named field as a tuple of strings ("a,b" from a command line splits)."""
    for name in names:
        value = getattr(config, name)
        if isinstance(value, str):
            text = value
            value = tuple(v.strip() for v in value.split(",") if v.strip())
            if text.strip() and not value:
                raise ConfigError(f"--{name.replace('_', '-')} {text!r}: no class names; expected names "
                                  "separated by commas, such as 'cup,chair'")
        object.__setattr__(config, name, tuple(str(v) for v in value))


def _nonnegative(config: object, names: tuple[str, ...]) -> None:
    for name in names:
        if getattr(config, name) < 0:
            raise ConfigError(f"{name} must be >= 0, got {getattr(config, name)}")


def _in_unit_interval(config: object, names: tuple[str, ...]) -> None:
    for name in names:
        if not 0.0 <= getattr(config, name) <= 1.0:
            raise ConfigError(f"{name} must be in [0, 1], got {getattr(config, name)}")


class _Part:
    """The end of the ``__post_init__`` chain: each part checks its own fields."""

    def __post_init__(self) -> None:
        pass


@dataclass(frozen=True)
class SamplingConfig(_Part):
    """Segment: which depth pixels become points, an organised subsample of the depth image
    (every ``pixel_step``-th pixel both ways: 4 → 160×120 points for 640×480) within a range."""

    pixel_step: int = 4
    """Downscale: keep every n-th pixel of the depth image in both directions."""
    min_depth_m: float = 0.3
    max_depth_m: float = 5.0
    """The paper's point cloud range of 5 m: blobs whose median depth is beyond it are dropped."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.pixel_step < 1:
            raise ConfigError(f"pixel_step must be >= 1, got {self.pixel_step}")


@dataclass(frozen=True)
class BackgroundFilterConfig(SamplingConfig):
    """Segment: dropping the points that lie inside background instances (walls, floors, tables)."""

    background_filter: bool = True
    """Remove points inside background instance boxes (off = the paper's ablation C4)."""
    background_margin_m: float = 0.02
    """Background boxes are grown by this much on every side before filtering (plus the depth
    noise, ``background_filter.BACKGROUND_MARGIN_PER_M2``): wider cuts thin parts that touch a
    wall or the floor (a bed's head board) from their objects, narrower lets wall noise through."""


@dataclass(frozen=True)
class SegmentConfig(BackgroundFilterConfig):
    """Segment (Algorithm 3): Euclidean clusters of the filtered points and their supports."""

    cluster_tolerance_m: float = 0.1
    """Euclidean clustering: neighbouring points closer than this join one cluster (plus
    ``segment.CLUSTER_TOLERANCE_PER_M`` per metre of depth)."""
    min_cluster_points: int = 15
    """Smaller clusters are noise."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.min_cluster_points < 1:
            raise ConfigError(f"min_cluster_points must be >= 1, got {self.min_cluster_points}")
        if self.cluster_tolerance_m <= 0:
            raise ConfigError("cluster_tolerance_m and gate_m must be positive")


@dataclass(frozen=True)
class RefineConfig(SegmentConfig):
    """Segment: the blobs refined with the detections, before they are associated."""

    detection_split: bool = False
    """Split a blob whose pixels fall into two or more detection boxes (touching objects). Off
    by default: on the simulated house it raised identity switches and localisation error
    (jittered and missed boxes make the split flicker from frame to frame)."""
    detection_join: bool = True
    """Join blobs inside one detection box that an occluder cut apart."""


@dataclass(frozen=True)
class MatchConfig(_Part):
    """Classify: naming blobs with the detections (Algorithm 4)."""

    iou_threshold: float = 0.5
    """A blob takes a detection's class when the IoU of their image boxes exceeds this."""
    keep_unknown: bool = True
    """Track blobs that matched no detection as class ``unknown`` (the paper does)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        _in_unit_interval(self, ("iou_threshold",))


@dataclass(frozen=True)
class TrackerConfig(_Part):
    """Associate, fuse and track the observations (``tracking.py``); the class vote's evidence."""

    # --- associate: which observation continues which track
    association: str = "hungarian"
    """How observations are assigned to tracks (``association.ASSOCIATIONS``): ``hungarian``
    (the paper's) or ``greedy``."""
    gate_m: float = 1.0
    """An observation farther than this from a track cannot join it."""
    max_age_s: float = 1.5
    """A track without an update for this long is closed."""
    # --- fuse: the evidence an object needs
    confirm_hits: int = 3
    """A track becomes an instance after this many associated observations ..."""
    unknown_confirm_whole: int = 3
    """... one detections do not name only after this many *whole* observations
    (``Measurement.whole``; 0: ``confirm_hits`` as for the rest)."""
    min_class_observations: int = 4
    """A track takes a class only after at least this many observations of it ..."""
    min_class_share: float = 0.6
    """... and when that class holds at least this share of the track's (score-weighted)
    known-class votes ..."""
    unknown_vote_weight: float = 0.15
    """... where an ``unknown`` observation weighs this much ..."""
    refused_min_views: int = 8
    """... and not a class none of its full views gave once it has this many, or two named
    another class (``whole.in_full_view``, ``class_vote._refused``; 0: off)."""
    class_sizes: bool = True
    """Common-sense sizes of the detector's classes (``plausible.CLASS_SIZES``): a blob longer
    than the largest instance of its class is ``unknown``; a track whose whole views were all
    shorter than the smallest instance cannot take the class."""
    # --- track: how objects move
    motion_model: str = "constant_velocity"
    """How a track moves (``motion.MOTION_MODELS``): the paper's constant-velocity Kalman filter."""
    measurement_noise_m: float = 0.03
    """Measurement noise: standard deviation of an observed centre."""
    accel_noise_mps2: float = 1.0
    """Process noise: standard deviation of the white acceleration of the constant-velocity model
    (``tracking.WALKER_ACCEL_NOISE_MPS2`` for walkers)."""
    walker_classes: tuple[str, ...] = ("person",)
    """Classes that walk: tracked as movers from their first view, never given a surface."""
    dynamic_speed_mps: float = 0.15
    """The evaluation counts a true person faster than this as walking (the moving-people speed
    figures); an instance's state is ``moving.is_dynamic``."""
    stitch: bool = True
    """A newly confirmed track that is an object already tracked joins that track's instance
    (``stitch.py``): a walker picked up again, a second blob of one walker, a static object seen
    again or a part of one."""
    reidentify: bool = True
    """At the end of a session, static objects and walkers of this session that are an earlier
    session's instances join them, and earlier objects whose place was seen empty are marked
    vacated (``reidentify.py``, ``vacated.py``)."""
    # --- classify: learned priors (``hiper analyze features``)
    use_learned_priors: bool = True
    """Use ``ods``/``size``/``altitude`` analyses from the knowledge base when they exist
    (``hiper analyze features``); off: the paper's C2 ablation. Each part can be switched alone:"""
    learned_gates: bool = True
    """The ODS's ``cu_mps · dt`` bounds the tracker's association gate (dt < 1 s)."""
    learned_motion_noise: bool = True
    """The ODS's stationary-noise ``sigma_mps`` sets the class's acceleration noise, for a class
    some instance of which moved (``dynamic_rows``)."""
    learned_size: bool = True
    """A detection whose blob volume is outside the class's learned range becomes ``unknown``."""
    learned_altitude: bool = True
    """A detection whose blob bottom is outside the class's learned altitude range becomes
    ``unknown`` (a person on a poster or a TV screen floats above the floor)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.gate_m <= 0:
            raise ConfigError("cluster_tolerance_m and gate_m must be positive")
        if self.confirm_hits < 1:
            raise ConfigError(f"confirm_hits must be >= 1, got {self.confirm_hits}")
        _as_tuples(self, ("walker_classes",))
        _nonnegative(self, ("refused_min_views",))
        _in_unit_interval(self, ("min_class_share",))


def _own(cls: type, base: type | None) -> frozenset[str]:
    """The fields ``cls`` adds to ``base``."""
    names = {f.name for f in fields(cls)}
    return frozenset(names - ({f.name for f in fields(base)} if base is not None else set()))


_SEGMENT = _own(RefineConfig, None)
_ASSOCIATE = frozenset({"association", "gate_m", "max_age_s"})
_FUSE = frozenset({"confirm_hits", "unknown_confirm_whole", "min_class_observations", "min_class_share",
                   "unknown_vote_weight", "refused_min_views", "class_sizes"})
_TRACK = frozenset({"motion_model", "measurement_noise_m", "accel_noise_mps2", "walker_classes",
                    "dynamic_speed_mps", "stitch", "reidentify"})
_DETECT = frozenset({"detector", "min_detection_score", "detector_threads", "detector_hz", "classes",
                     "exclude_classes"})
_CLASSIFY = _own(MatchConfig, None) | _own(TrackerConfig, None) - _ASSOCIATE - _FUSE - _TRACK | _DETECT


@dataclass(frozen=True)
class ForegroundConfig(TrackerConfig, MatchConfig, RefineConfig):
    """Everything the foreground stage can be told, by concept: segment, associate, fuse,
    track and classify (``PARTS``). What nobody should tune is a named constant beside the
    code that uses it, not an option.

    ``PARTS``: the option names of each concept, for dotted options (``track.stitch``); the
    older part names (``tracker``, ``match``, ``refine``, ``background_filter``) still work.
    """

    PARTS: ClassVar[dict[str, frozenset[str]]] = {
        "segment": _SEGMENT,
        "associate": _ASSOCIATE,
        "fuse": _FUSE,
        "track": _TRACK,
        "classify": _CLASSIFY,
        "background_filter": _own(BackgroundFilterConfig, SamplingConfig),
        "refine": _own(RefineConfig, SegmentConfig),
        "match": _own(MatchConfig, None),
        "tracker": _own(TrackerConfig, None),
    }

    detector: str = "yolox"
    """Registry name: ``yolox``, ``onnx:PATH``, ``log`` or ``truth``."""
    min_detection_score: float = 0.3
    """Detections below this score are ignored by the matching."""
    detector_threads: bool = True
    """Run the detector in a worker thread, concurrently with the point-cloud work."""
    detector_hz: float = 0.0
    """The detector looks this often (per s of log) and at every keyframe; the frames between are
    still segmented and tracked, named by the last look's boxes moved with the camera
    (``held.py``). 0: every frame. 10 saves about a quarter of a 30 Hz log's CPU but changed
    borderline names on some logs (``docs/results/2026-12-07-two-rates.md``)."""
    classes: tuple[str, ...] = ()
    """Only these detector classes name blobs (empty: all); a per-environment class list."""
    exclude_classes: tuple[str, ...] = INDOOR_EXCLUDED
    """Detector classes dropped before matching (the paper excluded classes not present, such as
    boat and traffic light): outdoor COCO classes and ``dining table`` (tables are background)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        _as_tuples(self, ("classes", "exclude_classes"))
        both = [c for c in self.classes if c in self.exclude_classes]
        if both:
            raise ConfigError(f"--classes and --exclude-classes both name {', '.join(both)}; a class is kept "
                              "or dropped, not both (the default exclusions: outdoor COCO classes and "
                              "'dining table')")

    @classmethod
    def from_options(cls, **options: Any) -> ForegroundConfig:
        """Build from keyword options, flat (``gate_m``) or dotted by part (``tracker.gate_m``);
        an unknown name raises ``ConfigError`` listing the known ones."""
        known = {f.name for f in fields(cls)}
        flat: dict[str, Any] = {}
        for key, value in options.items():
            part, dot, name = key.rpartition(".")
            if dot:
                if part not in cls.PARTS:
                    raise ConfigError(f"foreground option {key!r}: unknown part {part!r}; expected one of "
                                      f"{', '.join(cls.PARTS)}")
                if name not in cls.PARTS[part]:
                    raise ConfigError(f"foreground option {key!r}: {part} has no option {name!r}; expected "
                                      f"one of {', '.join(sorted(cls.PARTS[part]))}")
            if name in flat:
                raise ConfigError(f"foreground option {name!r} given twice")
            flat[name] = value
        unknown = sorted(set(flat) - known)
        if not unknown:  # names, types and finiteness by the shared validator
            from hiper_cli.validate import typed_options

            flat = typed_options(cls, flat, "-o foreground")
        if unknown:
            raise ConfigError(
                f"unknown foreground option(s) {unknown}; expected one of {', '.join(sorted(known))}"
            )
        return cls(**flat)
