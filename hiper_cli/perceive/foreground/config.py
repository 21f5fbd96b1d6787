"""Options of the foreground stage: frozen dataclasses, one per part, the paper's constants as defaults.

The point-cloud parts build on each other as the steps do: ``SamplingConfig`` (which depth
pixels) < ``BackgroundFilterConfig`` (dropping points of background instances) <
``SegmentConfig`` (Algorithm 3: clustering, supports, table legs and tops) < ``RefineConfig``
(trimming and joining blobs with the detections, which re-clusters). ``MatchConfig``
(Algorithm 4) and ``TrackerConfig`` (3D tracking) stand alone. ``ForegroundConfig`` is all of
them plus the detector's options. Each module is typed to take only the part it reads (the
tracker a ``TrackerConfig``), so mypy keeps the parts apart; a ``ForegroundConfig`` is each. Options are
flat names (``gate_m``) or dotted by part (``tracker.gate_m``, as in
``-o foreground.tracker.gate_m=0.8``).
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
    """Which depth pixels become points: an organised subsample of the depth image, every
    ``pixel_step``-th pixel in both directions (4 → 160×120 points for 640×480), far cheaper
    than a voxel grid and with the same effect on density, within a depth range."""

    pixel_step: int = 4
    """Downscale: keep every n-th pixel of the depth image in both directions."""
    min_depth_m: float = 0.3
    max_depth_m: float = 5.0
    """The paper's point cloud range of 5 m: blobs whose median depth is beyond it are dropped
    ..."""
    max_depth_slack_m: float = 0.3
    """... and points up to this much farther are kept, so that an object standing across the
    limit keeps its far side (a hard cut at 5 m moved a far chair's centre towards the camera)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.pixel_step < 1:
            raise ConfigError(f"pixel_step must be >= 1, got {self.pixel_step}")


@dataclass(frozen=True)
class BackgroundFilterConfig(SamplingConfig):
    """Dropping the points that lie inside background instances (walls, floors, tables)."""

    background_filter: bool = True
    """Remove points inside background instance boxes (off = the paper's ablation C4)."""
    background_margin_m: float = 0.02
    """Background boxes are grown by this much on every side before filtering: wider cuts thin
    parts that touch a wall or the floor (a bed's head board) from their objects, narrower lets
    wall noise through as blobs ..."""
    background_margin_per_m2: float = 0.0015
    """... plus this times the squared depth (structured-light depth noise grows with z²)."""
    background_noise_along_ray: bool = True
    """The z² part grows a box face by the noise projected on the face's normal (depth noise
    lies along the viewing ray: a floor seen at a grazing angle needs little of it) ..."""
    background_noise_min_cos: float = 0.25
    """... at least this share of it (edges, flying pixels)."""
    background_block_mean: bool = True
    """The filter tests each sample at the mean depth of its ``pixel_step`` × ``pixel_step``
    pixel block, on the block centre's ray, where that mean is within
    ``background_block_tolerance`` filter margins of the sample's own depth (elsewhere the block
    straddles an edge and the sample itself is tested). Sixteen pixels average the depth noise
    down about four times, so a bed's head board or a chair's feet stand out from the wall or
    floor behind them; the points themselves keep their own depth. Where a foot meets the floor
    the block mixes both, and a floor sample may stay with the object."""
    background_block_tolerance: float = 2.0
    table_leg_band_m: float = 0.0
    """Filter a band this wide under the edges of every background table top: its legs (0: off;
    needs accurate table boxes: with the background stage's table estimates it cut chairs)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        _nonnegative(self, ("table_leg_band_m",))
        if not 0.0 <= self.background_noise_min_cos <= 1.0:
            raise ConfigError(
                f"background_noise_min_cos must be in [0, 1], got {self.background_noise_min_cos}"
            )


@dataclass(frozen=True)
class SegmentConfig(BackgroundFilterConfig):
    """Segmentation (Algorithm 3): Euclidean clusters of the filtered points, their supports,
    then table legs, rims and unmapped table tops leave the blobs."""

    table_leg_cell_m: float = 0.05
    """Table legs leave the blobs (``legs.py``): points are binned horizontally in cells this
    wide (0: off) ..."""
    table_leg_reach_m: float = 0.1
    """... near a background table (its footprint grown by this) ..."""
    table_leg_min_height_m: float = 0.4
    """... a cell whose points reach from this far below the table top ..."""
    table_leg_top_band_m: float = 0.2
    """... up to within this of the top ..."""
    table_leg_above_m: float = 0.03
    """... and no more than this above it is a leg."""
    table_rim_depth_m: float = 0.08
    """After the unmapped tables (``drop_unseen_tables``): a cell near a table whose points all
    lie between this far below its top and ``table_rim_above_m`` above it is the top's edge
    (the background layer knows the top as a plane; the few centimetres of edge under it
    survive the filter, and at 4-5 m, with the cluster tolerance grown to 0.3 m, they joined a
    chair to the cups on the table) and leaves the blob with the legs; the rest is clustered
    again (0: off)."""
    table_rim_above_m: float = 0.01
    table_rim_reach_m: float = 0.1
    """Rim cells count this far outside the mapped top, and the legs under them too."""
    unseen_table_min_side_m: float = 0.3
    """A table the background layer has not mapped yet (its top seen at a grazing angle in the
    first seconds) merges the chairs around it into one blob. When such a blob overlaps a
    detection (IoU >= ``trim_iou``) and holds a horizontal slab between
    ``unseen_table_min_height_m`` and ``unseen_table_max_height_m`` whose footprint spans this
    much along both map axes, the slab and its legs leave the blob and the rest is clustered
    again (``legs.py``, ``refine.py``; 0: off) ..."""
    unseen_table_min_height_m: float = 0.6
    unseen_table_max_height_m: float = 1.2
    unseen_table_skip_classes: tuple[str, ...] = ("couch", "bed", "dining table", "toilet")
    """... except in blobs matched to these detector classes: furniture with tops of its own (a
    couch's arms and back are such a slab) ..."""
    unseen_table_lookalikes: tuple[str, ...] = ("bench",)
    """... A detection of these classes (no top at table height: a bench's seat lies below it)
    whose blob holds a table top named the table, and names nothing else in that frame
    (YOLOX-Nano names a table with things on it ``bench``) ..."""
    unseen_table_holding: float = 0.8
    """... and also in a blob that no detection names but that holds a detected object: a
    detection box (not of those classes) lies at least this share inside the blob's image box
    (a bottle or a cup standing on a table the background has not mapped, a bedside table seen
    only from a doorway, joins the table's blob, and no detection names that blob; 0: off)."""
    unseen_table_instances: bool = True
    """A table top found so (and its legs) is an observation of class ``table``, tracked as
    any object (``unmapped_tables.py``): a bedside table or a desk the background layer never
    maps is still a table. It is withdrawn once the background layer maps a table that it
    touches at the height of its top (within ``table_leg_reach_m``)."""
    table_pieces_max_gap_m: float = 0.8
    """Two such tables of one frame facing each other across at most this gap, their tops at
    one height and the band between them at that height hidden from the camera by something
    nearer (a chair in front of the table), are one table cut in two (``table_pieces.py``;
    0: off) ..."""
    table_pieces_max_length_m: float = 3.5
    """... unless joined they would be longer than this (two desks in a row, a chair before
    the gap between them)."""
    cluster_tolerance_m: float = 0.1
    """Euclidean clustering: neighbouring points closer than this join one cluster ..."""
    cluster_tolerance_per_m: float = 0.04
    """... plus this much per metre of depth (grazing surfaces, depth noise)."""
    cluster_neighbour_cells: int = 2
    """How far (in subsampled grid cells) a neighbour may be; bridges small depth holes."""
    fragment_ratio: float = 0.25
    """A cluster smaller than this share of a touching, nearby cluster is a fragment of it ..."""
    fragment_distance_m: float = 0.3
    """... when its centre is this close to that cluster's box (grazing sides, heads)."""
    support_gap_m: float = 0.1
    """A blob whose base is at most the filter margin plus this above a floor or table top
    stands on it: its box reaches down to the support (a wider gap, to catch chairs whose thin
    legs lose their lowest samples, moves the centre away from what the sensor sees)."""
    support_edge_band_m: float = 0.01
    """... unless its lowest points (within this of its lowest) reach the image's lower edge: its
    base is out of view (a chair cut there by its front legs, its back feet in view, stands)."""
    min_cluster_points: int = 15
    max_cluster_points: int = 8000
    max_cluster_extent_m: float = 3.0
    """Clusters longer than this in any direction are structure (walls, floor), not objects."""
    points_per_observation: int = 64
    """Subsample of ``points_cam`` stored in each observation."""
    pixels_per_observation: int = 48
    """Sample of pixel coordinates ``pixels_uv`` stored in each observation."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.min_cluster_points < 1 or self.max_cluster_points < self.min_cluster_points:
            raise ConfigError(
                f"cluster sizes: need 1 <= min_cluster_points <= max_cluster_points, got "
                f"{self.min_cluster_points} and {self.max_cluster_points}"
            )
        if self.cluster_tolerance_m <= 0:
            raise ConfigError("cluster_tolerance_m and gate_m must be positive")
        _nonnegative(self, ("table_rim_depth_m", "table_rim_reach_m"))
        _as_tuples(self, ("unseen_table_skip_classes", "unseen_table_lookalikes"))


@dataclass(frozen=True)
class RefineConfig(SegmentConfig):
    """Refinement of the blobs with the detections, between segmentation and matching."""

    trim_iou: float = 0.3
    """A blob overlapping a detection box with at least this IoU loses its points outside the
    (grown) box, when they are at most ``trim_max_share`` of it (1: off) ..."""
    trim_max_share: float = 0.4
    trim_margin_frac: float = 0.1
    """The trimming box is the detection box grown by this share of its size on every side:
    a jittered box (the ``truth`` detector's corners move by 5 % of the size, σ) otherwise cuts
    the head of a person or the top of a chair back. Only points at the depth of the blob's
    part inside the box (within ``trim_depth_m`` of its median) are kept there: a table leg or a
    wall behind is not."""
    trim_depth_m: float = 0.2
    detection_split: bool = False
    """Split a blob whose pixels fall into two or more detection boxes (touching objects). Off
    by default: on the simulated house it raised identity switches and localisation error
    (jittered and missed boxes make the split flicker from frame to frame)."""
    split_attach_m: float = 0.15
    """A split blob's point outside every box joins the nearest labelled point within this."""
    split_twins: bool = True
    """Even with ``detection_split`` off, split a blob that holds two or more detection boxes of
    one class side by side (each at least ``join_containment`` inside the blob's image box,
    none half inside another): bottles, cups or chairs in a row that the clustering joined (its
    tolerance grows with the depth: 0.26 m at 4 m). Boxes of one class side by side are two
    objects whatever the jitter; a person beside a chair keeps to the rule above."""
    twin_depth_gap_m: float = 0.5
    """Two boxes of one class that overlap by half or more are still twins when the points only
    one holds lie this much farther than the other's in median depth (two chairs one behind the
    other at a table's far end); nearer, they are duplicate boxes of one object (a chair's back
    is 0.2-0.45 m behind its seat's front; 0: never)."""
    carve_classes: tuple[str, ...] = (
        "bottle", "cup", "wine glass", "bowl", "vase", "laptop", "keyboard", "mouse", "remote",
        "cell phone", "clock", "scissors", "toothbrush", "potted plant", "teddy bear",
    )  # fmt: skip
    """A detection of one of these inside a blob longer than any instance of its class
    (``class_sizes``) cuts its object out of the blob (``carve.py``: a bottle on an unmapped
    side table; empty: off). Not ``book``: books stand in rows on a shelf, a box covers one
    spine or several, and a shelf's books are often part of the shelf (house 61 with
    ``yolox``: a ``book`` cut out of the shelf was a false positive) ..."""
    carve_depth_m: float = 0.2
    """... the points in its box within this of the box's front."""
    detection_join: bool = True
    """Join blobs inside one detection box that an occluder cut apart."""
    join_containment: float = 0.8
    """Share of a blob's pixels that must lie in the (grown) detection box to join ..."""
    detection_margin_frac: float = 0.1
    """... the box grown by this share of its size on every side (detector jitter: without it a
    chair's seat cut off by its own back at the image's lower edge stays apart) ..."""
    join_depth_m: float = 0.25
    """... their median depths at most this far apart ..."""
    join_gap_m: float = 0.3
    """... and their nearest points at most this far apart."""
    join_max_iou_loss: float = 0.05
    """... unless the joined image box's IoU with the detection box is lower than before by
    more than this (a piece of an unmapped table top beside a chair's box)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        _nonnegative(self, ("split_attach_m", "join_depth_m", "join_gap_m", "detection_margin_frac",
                            "twin_depth_gap_m", "trim_margin_frac", "trim_depth_m", "carve_depth_m"))
        _as_tuples(self, ("carve_classes",))
        if not 0.0 < self.join_containment <= 1.0:
            raise ConfigError(f"join_containment must be in (0, 1], got {self.join_containment}")


@dataclass(frozen=True)
class MatchConfig(_Part):
    """Matching blobs to detections (Algorithm 4)."""

    iou_threshold: float = 0.5
    """A blob takes a detection's class when the IoU of their image boxes exceeds this."""
    unknown_class: str = "unknown"
    keep_unknown: bool = True
    """Track blobs that matched no detection as class ``unknown`` (the paper does)."""
    fixture_classes: tuple[str, ...] = ("sink", "toilet")
    """Plumbing fixtures (``plausible.attached``): a blob named one of these classes is ``unknown``
    unless it stands against a wall (within ``fixture_reach_m`` of a background wall) or is
    built into a counter (its centre inside a background table top's footprint, its top within
    ``fixture_reach_m`` of the top's height). Pipes come out of walls; a round stool seen from
    above, standing free in the room, is no sink (empty: off)."""
    fixture_reach_m: float = 0.3
    couch_or_bed: bool = True
    """A blob a detection names ``couch`` or ``bed`` takes the other name when its tall part
    says so (``couch_or_bed.py``): a back along a long side is a couch's, a headboard across a
    short end a bed's (YOLOX-Nano names a couch ``bed`` in most of its views)."""
    unknown_max_extent_m: float = 1.0
    """An unmatched blob is seen *whole* (``whole.py``: evidence for an ``unknown`` instance)
    only when inside the image (not within one ``pixel_step`` of its edge: a shelf, a wall or a
    floor remnant cut by the border is a piece of something larger), no longer than this ..."""
    unknown_min_thickness_m: float = 0.01
    """... and not flat: the thinnest spread σ of its points at least this plus
    ``background_margin_per_m2`` · depth² (a flat blob is a piece of a wall, a floor or a
    furniture side the background did not claim)."""
    walker_solid: bool = True
    """A walker is a solid body (``solid.py``): a flat blob (as ``unknown_min_thickness_m``
    says: a picture or a screen showing people, a wall piece) named a walker class stays
    ``unknown``, and a walker's track does not take a flat blob."""
    detection_nearest: bool = True
    """A detection names one of the blobs it matches and those at its depth
    (``solid.detected_blobs``): for a walker class the nearest (a wall behind a person stays
    ``unknown``), for other classes the one that fits its box best (a desk's end in front of
    a chair stays ``unknown``); blobs more than ``join_depth_m`` behind or in front of it do not
    keep the name."""

    def __post_init__(self) -> None:
        super().__post_init__()
        _as_tuples(self, ("fixture_classes",))
        _nonnegative(self, ("fixture_reach_m",))
        if not 0.0 <= self.iou_threshold <= 1.0:
            raise ConfigError(f"iou_threshold must be in [0, 1], got {self.iou_threshold}")


@dataclass(frozen=True)
class TrackerConfig(_Part):
    """3D multi-object tracking of the observations (``tracking.py``)."""

    unknown_vote_weight: float = 0.15
    """A track's class is the score-weighted vote of its observations; ``unknown`` ones weigh
    this much each, so a few confused detections cannot name a mostly unmatched track."""
    unknown_confirm_whole: int = 3
    """A track detections do not name becomes an instance only after this many *whole*
    observations (``Measurement.whole``; 0: off, ``confirm_hits`` as for the rest) ..."""
    unknown_min_span_s: float = 0.5
    """... seen over at least this long (what shows in a few frames is not a lasting object) ..."""
    unknown_min_whole_share: float = 0.5
    """... and making at least this share of its observations (a track that mostly took pieces of
    something larger, cut by the border, is that larger thing)."""
    unknown_evidence_held: bool = True
    """The evidence must hold for the class an instance carries, all its life (checked at every
    update and when the track closes): detections count once they give the track its class, or
    while they name most of its observations (a person is named from its first view; a track
    that ends so without a class must have lasted ``unknown_min_span_s``); otherwise the whole
    evidence above, over all of its observations so far (a track confirmed on a few named
    views that then takes pieces of structure cut by the image border is that structure). A
    track that loses its evidence is withdrawn (``Tracker.withdrawn``): its instance is
    deleted, and comes back with the evidence. False: evidence is checked once, while the
    track is tentative, and ``min_class_observations`` detections count without a class."""
    motion_model: str = "constant_velocity"
    """How a track moves (``motion.MOTION_MODELS``): the paper's constant-velocity Kalman filter."""
    association: str = "hungarian"
    """How observations are assigned to tracks (``association.ASSOCIATIONS``): ``hungarian``
    (the paper's) or ``greedy``."""
    gate_m: float = 1.0
    """Hungarian assignment: an observation farther than this from a track cannot join it ..."""
    gate_sigmas: float = 4.0
    min_gate_m: float = 0.5
    """... and a settled track gates at gate_sigmas times its predicted position σ, at least
    min_gate_m (a chair does not take the bottle on the table beside it)."""
    min_class_observations: int = 4
    """A track takes a class only after at least this many observations of it (one confused
    detection cannot name a track) ..."""
    min_class_share: float = 0.6
    """... and when that class holds at least this share of the track's (score-weighted)
    known-class votes: a track whose detections keep swapping between two classes (a person
    half of the time taken for a teddy bear) stays ``unknown`` instead of guessing."""
    refused_min_views: int = 8
    """A track cannot take a class that detections gave it in at most ``refused_max_share`` of
    its full views (``whole.in_full_view``: inside the image, not hidden in part, large enough)
    once it has this many (0: off): a shelf named ``chair`` only while the image's border cut
    it, and named nothing in every view that showed all of it, is no chair ..."""
    refused_max_share: float = 0.0
    full_view_min_px2: float = 1024.0
    """... where a full view's image box covers at least this many pixels (32 x 32; smaller, a
    detector may miss what it names up close) ..."""
    full_view_cover: float = 0.5
    """... and a full view counts for every class of a detection lying (this share of its box's
    area) inside the blob's image box, named for the blob or not (``match.named_within``): a
    bottle joined with the cup beside it in one blob was still named a bottle."""
    class_sizes: bool = True
    """Common-sense sizes of the detector's classes (``plausible.CLASS_SIZES``): an observation
    whose blob is longer than the largest instance of the class it was named is ``unknown``,
    and a track cannot take a class when every view that named it so, with the blob seen whole
    (inside the image, not hidden in part by something nearer), showed an object shorter than
    the smallest instance (a 1 m book display is no bed, a trash can no cup). A view can show
    less of an object, never more."""
    class_size_tolerance: float = 0.15
    """The sizes' margin for measurement: the largest times 1 + this, the smallest times 1 - this."""
    class_mismatch_m: float = 0.5
    """Association cost added (inside the gate) when a track and an observation have
    different known classes: same-class pairs win, a confused detection still joins."""
    gate_margin_m: float = 0.15
    """Added to the learned c_u·dt gate (position noise of two measurements)."""
    confirm_hits: int = 3
    """A track becomes an instance after this many associated observations."""
    max_age_s: float = 1.5
    """A track without an update for this long is closed."""
    tentative_max_age_s: float = 0.3
    """A tentative (unconfirmed) track without an update for this long is dropped."""
    lost_max_s: float = 20.0
    """A track unseen for this long is closed even while out of view."""
    tentative_lost_max_s: float = 2.0
    """A tentative track unseen for this long is dropped even while out of view."""
    search_speed_mps: float = 0.6
    """The gate of an unseen track that was moving widens by this much per second unseen ..."""
    max_gate_m: float = 3.0
    """... up to this."""
    search_classes: tuple[str, ...] = ("person", "unknown")
    """Classes whose lost tracks search (widen their gate while unseen) when they were moving:
    the centre of a bed's or couch's blob slides as the view changes, which looks like motion."""
    search_same_class: tuple[str, ...] = ("person",)
    """Beyond its normal gate a searching track of these classes only takes an observation of
    its own class: a lost person track otherwise took a chair or junk blob metres away."""
    search_min_size_ratio: float = 0.5
    """... or an ``unknown`` one at least this share of the track's largest blob (a person coming
    back cut by the image border, unmatched; 0.75 split the fixture's person; above 1: never) ..."""
    search_unknown_max_s: float = 3.0
    """... and that only within this long of its last update: a person comes back through the
    border soon after leaving it, while after longer only a detection says a blob is the person,
    inside the normal gate too (a track lost for 13 s took a 1.5 m wall and ceiling corner 3 m
    away; one lost for 11 s, another person's unnamed blob 0.9 m away) ..."""
    search_max_footprint_m: float = 1.2
    """... and no wider than this seen from above (the diagonal of its box's footprint): a
    person is about a metre across at most; a lost person's track took a couch's blob, 1.0 by
    1.7 m, and kept it while the person went on as a new track."""
    moving_speed_mps: float = 0.3
    """Only a track that was moving faster than this when last seen (filtered velocity and
    displacement over ``moving_window_s``) widens its gate while unseen: static objects do not
    walk away, people walk at 0.5-1.4 m/s ..."""
    moving_window_s: float = 1.0
    min_moving_span_s: float = 0.5
    """... and a track observed for less than this long is not known to move."""
    dynamic_moving_s: float = 1.0
    dynamic_travel_m: float = 0.5
    """A track is ``dynamic`` once it was moving (as above) and both sides of its blobs' box
    went this far horizontally, one not of a walker class only after it kept moving at every
    update for ``dynamic_moving_s`` and when its blobs moved (``SeenBox.moved``; not asked of
    ``unknown``) (``moving.is_dynamic``); it stays so after it stops or is lost: a person who
    walked is a dynamic object. A static blob that changes as the camera passes moves in spells
    of a few frames, and one that grew as more of it came into view went nowhere."""
    velocity_decay_s: float = 0.5
    """Time constant of the exponential decay of a track's velocity while it gets no updates."""
    velocity_prior_mps: float = 1.0
    """While the velocity decays, its uncertainty relaxes towards this (walking speeds), so a
    track picked up again learns its new velocity at once ..."""
    velocity_relax_static: bool = False
    """... also for tracks of classes that do not search (``search_classes``), if true. False:
    a chair's or a cup's only decays, and its gate does not grow to ``gate_m`` within half a
    second unseen (else the piece of a chair leaving the view can take the cup on the table
    0.85 m away)."""
    velocity_decay_grace_s: float = 0.1
    """No decay for this long after the last update (a missed detection must not slow a walker)."""
    accel_noise_mps2: float = 1.0
    """Process noise: standard deviation of the white acceleration of the constant-velocity model ..."""
    walker_accel_noise_mps2: float = 2.0
    """... and for tracks of a class in ``walker_classes``: people start, stop and turn sharply
    (the simulated ones turn at up to 3 rad/s, 2.7 m/s² at 0.9 m/s); with 1.0 the filter lagged
    and the smoother cut the corners: speeds biased low."""
    vertical_noise_ratio: float = 0.3
    """Vertical process noise relative to horizontal (objects mostly move on the floor)."""
    prior_accel_time_s: float = 0.5
    """With a learned speed spread sigma, the acceleration noise is sigma / this time."""
    measurement_noise_m: float = 0.03
    """Measurement noise: standard deviation of an observed centre."""
    walker_min_size_ratio: float = 0.2
    """A track of a walker class does not take a blob smaller than this share of the largest
    blob it took (size: the larger of footprint diagonal and height): a 20-point junk blob or a
    cup is not the person who just left the view (0: off)."""
    walker_classes: tuple[str, ...] = ("person",)
    """Classes that walk: their tracks use ``walker_accel_noise_mps2`` and
    ``walker_min_size_ratio``."""
    walker_max_base_m: float = 1.2
    """A blob named by a walker class whose lowest point lies more than this above the floor
    (the lowest floor instance's top; the map's z = 0 before one) is no walker: it stays
    ``unknown`` (0: off). People stand on the floor; behind a counter they still show below."""
    walker_from_floor: bool = True
    """An observation a detection names a walker class spans from the floor to its blob's top
    (the centre halfway): people stand on the floor, and a person behind a shelf or a table
    shows only the upper body, whose blob alone puts the centre 0.5-0.8 m too high."""
    walker_level: bool = True
    """Tracks of a walker class (or, before a track has a class, observations of one) have no
    vertical velocity: people walk on the floor, so their centre is half their height up (a high
    quantile of their blobs' tops) and is never extrapolated (a vertical velocity drives boxes
    below the floor, and the mean of partial blobs puts a person 0.7 m low)."""
    complete_footprints: bool = True
    """A static bed, couch or refrigerator seen in part has its box extended behind the faces
    the camera saw, to its class's least footprint width, and a chair, couch or refrigerator
    whose top no view showed is raised to its class's least height (``amodal.py``): a bed seen
    through a doorway as a strip of its side is otherwise centred half a metre off, and a chair
    behind a desk ends at its seat."""
    reidentify: bool = True
    """At the end of a session, a static object of a class that stays put whose box overlaps an
    earlier session's instance of its class (``stitch_min_overlap``, ``stitch_overlap_m``) joins
    that instance (``reidentify.py``): a second log of one place, or ``perceive --again``, gave
    every chair and bed a second instance. An earlier instance whose place this session saw
    empty (``vacated.py``) joins the nearest new instance of its class that no earlier one
    took, within ``reidentify_moved_m`` (the object moved); unpaired, it is marked vacated
    (``data["vacated_s"]``: the first stamp its place was seen empty). A walker joins an
    earlier walker of its class only when seen at the same times and place
    (``stitch_duplicate_m`` at ``confirm_hits`` or more common stamps): one log perceived again."""
    reidentify_moved_m: float = 3.0
    settled_hits: int = 15
    """A track not of a walker class, with at least this many observations and not moving (a
    named one: its blobs stayed where they were, ``SeenBox.moved``; an ``unknown`` one: its
    filter, ``moving_speed_mps``), is settled: it only takes an observation whose box overlaps the
    box of its blobs (``SeenBox``; the filter's centre drifts as partial views come and go: a
    TV's track took a wall sliver 0.7 m away) grown by ``settled_overlap_m``. Something that
    stood still is where it stood: the 2 cm
    sliver of a door frame must not take the person walking past it half a metre away, and
    turn its standing rows into the person's (0: off) ..."""
    settled_overlap_m: float = 0.05
    stitch: bool = True
    """A newly confirmed track that is an object already tracked joins that track's instance
    (``stitch.py``): a walker picked up again, a second blob of one walker, a static object seen
    again or a part of one ..."""
    stitch_max_gap_s: float = 3.0
    """... a walker's new track starting at most this long after one of the old one's rows ..."""
    stitch_speed_mps: float = 1.5
    stitch_margin_m: float = 0.5
    """... within ``stitch_margin_m`` plus this speed times the gap of that row's position ..."""
    stitch_pace_factor: float = 1.5
    stitch_min_pace_mps: float = 0.6
    """... where the speed is the old walker's own pace, at most this factor times its median
    speed (at least ``stitch_min_pace_mps``, at most ``stitch_speed_mps``): a person who walked
    at 0.6 m/s did not cover 5 m in 3 s, another person came into view (0: any walker may go
    ``stitch_speed_mps``) ..."""
    stitch_appearance_gap_s: float = 60.0
    stitch_min_similarity: float = 0.8
    """... or after a longer gap, up to ``stitch_appearance_gap_s``, with colour histograms
    (Bhattacharyya coefficient) at least this similar: one person's tracks 0.92-1.0 and two
    people's 0.46-0.55 on the realistic worlds ..."""
    stitch_duplicate_m: float = 0.4
    """... or, tracked at the same time, within this of it (median, horizontal) ..."""
    stitch_overlap_m: float = 0.3
    """... and a static track whose box's footprint overlaps the other's, at most this far
    apart vertically (a chair's back over a table, its seat under it) ..."""
    stitch_min_overlap: float = 0.5
    """... by this share of the smaller footprint (of the larger when one is ``unknown``)."""
    stitch_static_again: bool = True
    """A confirmed track of any class is offered to stitching again each time its observations
    double (not only walkers), either way round (the older track keeps its instance), and a
    pair of static tracks is judged static on the boxes of their blobs together
    (``same_object.py``): a track's box is young when it is confirmed, and a track that saw only
    part of a large object seems to move on its own (false: offered once, at confirmation)."""
    smooth_closed_tracks: bool = True
    """Refine a closed track's trajectory with a Rauch-Tung-Striebel smoother."""
    dynamic_speed_mps: float = 0.15
    """The evaluation counts a true person faster than this as walking (the moving-people speed
    figures); an instance's state is ``moving.is_dynamic``."""
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
    prior_tolerance: float = 0.5
    """Size / altitude priors reject a class when a blob is outside [lo·(1-t), hi·(1+t)]."""
    prior_min_instances: int = 3
    """A class's learned feature is a prior only when learned from this many instances: the
    range of one TV's altitude is a point, and the views of the next TV, stand in or out, are
    not."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.gate_m <= 0:
            raise ConfigError("cluster_tolerance_m and gate_m must be positive")
        if self.confirm_hits < 1:
            raise ConfigError(f"confirm_hits must be >= 1, got {self.confirm_hits}")
        _as_tuples(self, ("search_classes", "walker_classes", "search_same_class"))
        _nonnegative(self, ("stitch_max_gap_s", "stitch_appearance_gap_s", "stitch_speed_mps",
                            "stitch_margin_m", "stitch_duplicate_m", "stitch_overlap_m",
                            "stitch_pace_factor", "stitch_min_pace_mps", "search_max_footprint_m",
                            "reidentify_moved_m", "refused_min_views", "full_view_min_px2",
                            "prior_min_instances"))
        _in_unit_interval(self, ("stitch_min_overlap", "class_size_tolerance", "refused_max_share",
                                 "full_view_cover"))


def _own(cls: type, base: type | None) -> frozenset[str]:
    """The fields ``cls`` adds to ``base``."""
    names = {f.name for f in fields(cls)}
    return frozenset(names - ({f.name for f in fields(base)} if base is not None else set()))


@dataclass(frozen=True)
class ForegroundConfig(TrackerConfig, MatchConfig, RefineConfig):
    """Everything the foreground stage can be told: the detector's options and every part's.

    ``PARTS``: the option names of each part, for dotted options (``tracker.gate_m``).
    """

    PARTS: ClassVar[dict[str, frozenset[str]]] = {
        "segment": _own(SegmentConfig, BackgroundFilterConfig) | _own(SamplingConfig, None),
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
    classes: tuple[str, ...] = ()
    """Only these detector classes name blobs (empty: all); a per-environment class list."""
    exclude_classes: tuple[str, ...] = INDOOR_EXCLUDED
    """Detector classes dropped before matching (the paper excluded classes not present, such as
    boat and traffic light): outdoor COCO classes and ``dining table`` (tables are background)."""
    carried_classes: tuple[str, ...] = ("backpack", "umbrella", "handbag", "tie", "suitcase", "cell phone")
    """Things people carry (``carried.py``): a detection of one of these classes whose box lies
    inside a walker detection's box (``carried_containment`` of its area) is part of that person
    (a bag on a walker's arm, a phone at an ear) and is dropped before refinement, so the
    person's box names the blob; empty: off."""
    carried_containment: float = 0.8
    same_box_iou: float = 0.8
    """Two detections of different classes whose boxes overlap by this IoU are one object the
    detector named twice (``classes.one_name_per_box``: a bottle and a vase, a bench and a
    chair): the one with the higher score stays; ``walker_classes`` are left out; 1: off."""

    def __post_init__(self) -> None:
        super().__post_init__()
        _as_tuples(self, ("classes", "exclude_classes", "carried_classes"))
        _in_unit_interval(self, ("carried_containment", "same_box_iou"))
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
