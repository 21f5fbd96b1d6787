"""3D multi-object tracking of foreground observations in the map frame.

- Association: an assignment rule chosen by name (``association``: the paper's Hungarian
  algorithm by default, see ``association.py``) on the distances between the tracks' predicted
  centres and the observed centres, with a gate: ``gate_m``, at most the learned
  ``c_u · dt + gate_margin_m`` of the class when the knowledge base has an ``ods`` analysis
  and dt < 1 s (the paper rejects pairs beyond it); the gate widens by ``search_speed_mps``
  per second a track goes unseen (up to ``max_gate_m``) so that a person who left the view is
  picked up again; only a track of a class in ``search_classes`` (people, and ``unknown``)
  that was moving when last seen searches like that (a chair or a bed does not walk away while
  unseen: a static track that widened its gate would take a different object metres away when
  the robot comes back); a settled track gates at ``gate_sigmas`` times its predicted position
  σ (at least ``min_gate_m``).
  Inside the gate, two different known classes cost ``class_mismatch_m`` more (same-class
  pairs are preferred, a confused detection still joins its track); ``unknown`` is neutral.
  A track of a walker class (``walker_classes``) does not take a blob smaller than
  ``walker_min_size_ratio`` of the largest blob it took (a junk blob, a cup or a border fragment
  is not the person: such rows collapsed the person's speed).
- Filter: a ``MotionModel`` per track chosen by name (``motion_model``, ``motion.py``; by
  default a constant-velocity Kalman filter over position and velocity) with white
  acceleration noise (class-specific from the learned ``sigma_mps`` when known, else
  ``walker_accel_noise_mps2`` for walkers and ``accel_noise_mps2`` for the rest). A track's
  velocity is initialised from its first two observations (the paper started at zero, which
  biased the speeds low) with the matching covariance.
- Unseen tracks: their velocity decays exponentially to zero (time constant
  ``velocity_decay_s``) once they have been unseen for longer than the grace
  (``velocity_decay_grace_s``, at least ``DECAY_GRACE_FRAMES`` frames), so a missed
  detection does not bias a moving track. A track only ages while its predicted centre is
  visible to the camera (in the image, not hidden behind nearer depth): a person who walks out
  of view keeps the identity for ``lost_max_s``.
- Class: a vote over its observations' classes, with minimum evidence (``class_vote.py``).
- Closed tracks: their trajectory is refined by a Rauch-Tung-Striebel smoother
  (``smoother.py``: every row then uses all observations of the track).
- Life cycle: tentative → confirmed after ``confirm_hits`` observations (an ``unknown`` one
  after ``unknown_confirm_whole`` whole ones over ``unknown_min_span_s``) → closed after
  ``max_age_s`` unseen in view (or ``lost_max_s`` anywhere). Only confirmed tracks are instances;
  one whose evidence fails later, or on closing, is withdrawn (``unknown_evidence_held``).
- Stitching (``stitch``): a newly confirmed (or newly named) track that continues a known one
  (a walker picked up again, a second blob of it, a static object seen again) is absorbed by it
  (``stitch.py``); closed confirmed tracks wait for that: static ones for good, walkers
  ``stitch_appearance_gap_s``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.model import ROW_POSITION, ROW_VELOCITY, new_uuid
from hiper_cli.perceive.foreground.association import get_association
from hiper_cli.perceive.foreground.class_vote import UNKNOWN, named_object, record
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.motion import MOTION_MODELS, make_motion_model
from hiper_cli.perceive.foreground.moving import MOVING_SPEED_MPS, is_static, note_travel, was_moving
from hiper_cli.perceive.foreground.plausible import CLASS_SIZE_TOLERANCE
from hiper_cli.perceive.foreground.same_object import (
    STAMP_DECIMALS,
    due,
    fold,
    footprint_m2,
    newer_match,
    static_together,
)
from hiper_cli.perceive.foreground.smoother import smooth_trajectory
from hiper_cli.perceive.foreground.stitch import (
    DUPLICATE,
    RESUME,
    REVISIT,
    absorb,
    find_target,
    gap_ok,
    provisional_class,
    stale_rows,
)
from hiper_cli.perceive.foreground.track import ClassPrior, Measurement, NamedBlob, Track

__all__ = ["ClassPrior", "Measurement", "Track", "Tracker", "object_box"]  # the first three: ``track.py``

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
UNKNOWN_MIN_SPAN_S: float = 0.5
"""... seen over at least this long (what shows in a few frames is not a lasting object) ..."""
UNKNOWN_MIN_WHOLE_SHARE: float = 0.5
"""... and making at least this share of its observations (a track that mostly took pieces of
something larger, cut by the border, is that larger thing)."""
UNKNOWN_EVIDENCE_HELD: bool = True
"""The evidence must hold for the class an instance carries, all its life (checked at every
update and when the track closes): detections count once they give the track its class, or
while they name most of its observations (a person is named from its first view; a track
that ends so without a class must have lasted ``unknown_min_span_s``); otherwise the whole
evidence above, over all of its observations so far (a track confirmed on a few named
views that then takes pieces of structure cut by the image border is that structure). A
track that loses its evidence is withdrawn (``Tracker.withdrawn``): its instance is
deleted, and comes back with the evidence. False: evidence is checked once, while the
track is tentative, and ``min_class_observations`` detections count without a class."""
GATE_SIGMAS: float = 4.0
MIN_GATE_M: float = 0.5
"""... and a settled track gates at gate_sigmas times its predicted position σ, at least
min_gate_m (a chair does not take the bottle on the table beside it)."""
CLASS_MISMATCH_M: float = 0.5
"""Association cost added (inside the gate) when a track and an observation have
different known classes: same-class pairs win, a confused detection still joins."""
GATE_MARGIN_M: float = 0.15
"""Added to the learned c_u·dt gate (position noise of two measurements)."""
TENTATIVE_MAX_AGE_S: float = 0.3
"""A tentative (unconfirmed) track without an update for this long is dropped."""
LOST_MAX_S: float = 20.0
"""A track unseen for this long is closed even while out of view."""
TENTATIVE_LOST_MAX_S: float = 2.0
"""A tentative track unseen for this long is dropped even while out of view."""
SEARCH_SPEED_MPS: float = 0.6
"""The gate of an unseen track that was moving widens by this much per second unseen ..."""
MAX_GATE_M: float = 3.0
"""... up to this."""
SEARCH_CLASSES: tuple[str, ...] = ("person", "unknown")
"""Classes whose lost tracks search (widen their gate while unseen) when they were moving:
the centre of a bed's or couch's blob slides as the view changes, which looks like motion."""
SEARCH_SAME_CLASS: tuple[str, ...] = ("person",)
"""Beyond its normal gate a searching track of these classes only takes an observation of
its own class: a lost person track otherwise took a chair or junk blob metres away."""
SEARCH_MIN_SIZE_RATIO: float = 0.5
"""... or an ``unknown`` one at least this share of the track's largest blob (a person coming
back cut by the image border, unmatched; 0.75 split the fixture's person; above 1: never) ..."""
SEARCH_UNKNOWN_MAX_S: float = 3.0
"""... and that only within this long of its last update: a person comes back through the
border soon after leaving it, while after longer only a detection says a blob is the person,
inside the normal gate too (a track lost for 13 s took a 1.5 m wall and ceiling corner 3 m
away; one lost for 11 s, another person's unnamed blob 0.9 m away) ..."""
SEARCH_MAX_FOOTPRINT_M: float = 1.2
"""... and no wider than this seen from above (the diagonal of its box's footprint): a
person is about a metre across at most; a lost person's track took a couch's blob, 1.0 by
1.7 m, and kept it while the person went on as a new track."""
VELOCITY_DECAY_S: float = 0.5
"""Time constant of the exponential decay of a track's velocity while it gets no updates."""
VELOCITY_PRIOR_MPS: float = 1.0
"""While the velocity decays, its uncertainty relaxes towards this (walking speeds), so a
track picked up again learns its new velocity at once ..."""
VELOCITY_RELAX_STATIC: bool = False
"""... also for tracks of classes that do not search (``search_classes``), if true. False:
a chair's or a cup's only decays, and its gate does not grow to ``gate_m`` within half a
second unseen (else the piece of a chair leaving the view can take the cup on the table
0.85 m away)."""
VELOCITY_DECAY_GRACE_S: float = 0.1
"""No decay for this long after the last update (a missed detection must not slow a walker)."""
WALKER_ACCEL_NOISE_MPS2: float = 2.0
"""... and for tracks of a class in ``walker_classes``: people start, stop and turn sharply
(the simulated ones turn at up to 3 rad/s, 2.7 m/s² at 0.9 m/s); with 1.0 the filter lagged
and the smoother cut the corners: speeds biased low."""
VERTICAL_NOISE_RATIO: float = 0.3
"""Vertical process noise relative to horizontal (objects mostly move on the floor)."""
PRIOR_ACCEL_TIME_S: float = 0.5
"""With a learned speed spread sigma, the acceleration noise is sigma / this time."""
WALKER_MIN_SIZE_RATIO: float = 0.2
"""A track of a walker class does not take a blob smaller than this share of the largest
blob it took (size: the larger of footprint diagonal and height): a 20-point junk blob or a
cup is not the person who just left the view (0: off)."""
WALKER_LEVEL: bool = True
"""Tracks of a walker class (or, before a track has a class, observations of one) have no
vertical velocity: people walk on the floor, so their centre is half their height up (a high
quantile of their blobs' tops) and is never extrapolated (issue 17: person boxes below the
floor, and 0.7 m low from the mean of partial blobs)."""
SETTLED_HITS: int = 15
"""A track not of a walker class, with at least this many observations and not moving (a
named one: its blobs stayed where they were, ``SeenBox.moved``; an ``unknown`` one: its
filter, ``moving_speed_mps``), is settled: it only takes an observation whose box overlaps the
box of its blobs (``SeenBox``; the filter's centre drifts as partial views come and go: a
TV's track took a wall sliver 0.7 m away) grown by ``settled_overlap_m``. Something that
stood still is where it stood: the 2 cm
sliver of a door frame must not take the person walking past it half a metre away, and
turn its standing rows into the person's (0: off) ..."""
SETTLED_OVERLAP_M: float = 0.05
STITCH_STATIC_AGAIN: bool = True
"""A confirmed track of any class is offered to stitching again each time its observations
double (not only walkers), either way round (the older track keeps its instance), and a
pair of static tracks is judged static on the boxes of their blobs together
(``same_object.py``): a track's box is young when it is confirmed, and a track that saw only
part of a large object seems to move on its own (false: offered once, at confirmation)."""
SMOOTH_CLOSED_TRACKS: bool = True
"""Refine a closed track's trajectory with a Rauch-Tung-Striebel smoother."""

FloatArray = NDArray[np.float64]

# Named constants of the tracker (not the paper's; chosen by measurement, see docs/foreground.md).
MIN_PRIOR_SIGMA_MPS = 0.05  # a learned speed spread below this would freeze a class's filter
DECAY_GRACE_FRAMES = 1.5  # the decay grace covers at least one missed frame at any frame rate
LOST_AFTER_FRAMES = 2.5  # a track is lost after more than one missed frame (gap of 2 frames)
EXTENT_GAIN = 0.2  # exponential smoothing of a track's box extent by each new observation
MIN_VELOCITY_INIT_DT_S = 1e-6  # two observations closer in time give no velocity
WALKER_VZ_VAR = 1e-4  # (m/s)²: a walker's vertical velocity held at zero (``walker_level``)
# A walker's height: this quantile of its blobs' tops above the floor. A high one, since blobs
# of a person are often only a part (legs under a table, a body cut at the image's lower edge).
WALKER_HEIGHT_QUANTILE = 0.8
MAX_STANDING_TOPS = 300  # tops kept for the quantile (20 s at 15 Hz)


@lru_cache(maxsize=64)
def _decay_terms(
    dt: float, decay_s: float, prior: float, ratio: float
) -> tuple[float, FloatArray, FloatArray]:
    """The velocity decay over ``dt`` (``Tracker._decay``): the factor a = exp(-dt/decay_s), the
    covariance scale (position-velocity terms by a, velocity variances by a²) and the relaxation
    (1 - a²)·prior on the velocity variances (vertical: times ``ratio``). Cached (most frames
    share one dt): read-only."""
    factor = math.exp(-dt / decay_s)
    scale = np.array([1.0, 1.0, 1.0, factor, factor, factor])
    scale_P = np.outer(scale, scale)
    relax = np.diag((1.0 - factor**2) * np.array([0.0, 0.0, 0.0, prior, prior, prior * ratio]))
    scale_P.setflags(write=False)
    relax.setflags(write=False)
    return factor, scale_P, relax


def _record_standing(track: Track, m: Measurement) -> None:
    if m.standing is None:
        return
    center, extent = m.standing
    track.standing_tops_m.append(float(center[2] + extent[2] / 2.0))
    del track.standing_tops_m[:-MAX_STANDING_TOPS]  # a long walk: its latest blobs
    track.floor_z_m = float(center[2] - extent[2] / 2.0)


def standing_level(track: Track) -> tuple[float, float] | None:
    """(centre z, height) of a walker standing on the floor: the height is the
    ``WALKER_HEIGHT_QUANTILE`` of its blobs' tops; None before a standing box was seen."""
    if not track.standing_tops_m or track.floor_z_m is None:
        return None
    top = float(np.quantile(track.standing_tops_m, WALKER_HEIGHT_QUANTILE))
    height = top - track.floor_z_m
    return track.floor_z_m + height / 2.0, height


def object_box(track: Track, config: TrackerConfig) -> tuple[FloatArray, FloatArray]:
    """(centre, extent), map frame, of the object a track is: a static one's seen box (the union
    of its blobs, ``SeenBox``); a walker's or a moving object's filtered box where it was last
    updated (not extrapolated past its last observation), as wide as its whole views showed it and,
    a walker seen standing, as tall as it stood (``standing_level``), not the mean of the legs,
    upper bodies or slivers at the image's border its last views showed.
    An ``unknown`` track detections named a static class (``Track.search_class``) is judged as
    that class: a book display turned down as a bed, whose blob slid while the robot turned past
    it, is where its blobs were."""
    named = track.search_class
    if is_static(track, config) or (
        named != track.class_name and named not in config.walker_classes and not track.seen.moved()
    ):
        found = track.seen.box()
        if found is not None:
            return found
    centre = np.array(track.trajectory[-1][ROW_POSITION] if track.trajectory else track.position, float)
    extent = np.array(track.extent_m, float)
    if track.whole_footprint_m is not None:  # not the slivers of it at the image's border
        extent[:2] = track.whole_footprint_m
    level = standing_level(track) if track.class_name in config.walker_classes else None
    if level is not None:  # a whole person stands on the floor, whatever part the last views showed
        centre[2], extent[2] = level
    return centre, extent


def _size_m(extent_m: FloatArray) -> float:
    """How big a box is: the larger of its footprint diagonal and its height."""
    return max(math.hypot(float(extent_m[0]), float(extent_m[1])), float(extent_m[2]))


class Tracker:
    """Gated association + one motion model per track (see the module docstring)."""

    def __init__(
        self,
        config: TrackerConfig,
        priors: Callable[[str], ClassPrior] | None = None,
    ) -> None:
        if config.motion_model not in MOTION_MODELS:
            raise ConfigError(f"motion_model {config.motion_model!r}: unknown; expected one of "
                              f"{', '.join(MOTION_MODELS)}")
        self.config = config
        self._assign = get_association(config.association)
        self.priors = priors or (lambda _name: ClassPrior())
        self.tracks: list[Track] = []  # live (tentative or confirmed)
        self.dormant: list[Track] = []  # closed confirmed tracks a new one may continue
        self.absorbed: list[str] = []  # uuids of the tracks stitched into others this step
        self.withdrawn: list[str] = []  # uuids of the instances whose evidence failed this step
        self.last_stamp_s: float | None = None
        self._frame_dt_s = 0.0

    # --- motion ---------------------------------------------------------------------------
    def _accel_noise(self, class_name: str) -> float:
        prior = self.priors(class_name)
        if self.config.use_learned_priors and prior.sigma_mps is not None:
            return max(float(prior.sigma_mps), MIN_PRIOR_SIGMA_MPS) / PRIOR_ACCEL_TIME_S
        if class_name in self.config.walker_classes:
            return WALKER_ACCEL_NOISE_MPS2
        return self.config.accel_noise_mps2

    def _predict(self, track: Track, stamp_s: float) -> None:
        dt = stamp_s - track.last_time_s
        if dt <= 0:
            return
        q = self._accel_noise(track.class_name) ** 2
        track.motion.predict(dt, q, self._vertical_noise(track, q))
        track.last_time_s = stamp_s

    def _walks(self, track: Track, m: Measurement | None = None) -> bool:
        """Whether ``track`` is held level (``walker_level``): its class walks, or, while it has
        none yet, this observation's does."""
        if not WALKER_LEVEL:
            return False
        name = track.class_name
        if name == UNKNOWN and m is not None:
            name = m.class_name
        return name in self.config.walker_classes

    def _vertical_noise(self, track: Track, q: float) -> float:
        return 0.0 if self._walks(track) else q * VERTICAL_NOISE_RATIO**2

    def _hold_level(self, track: Track) -> None:
        """No vertical velocity: people walk on the floor, so a walker's centre is half its
        height above the floor (``standing_level``), never extrapolated (a centre below the floor
        or metres above it came from a vertical velocity a blob's growing or shrinking gave the
        filter, or from the mean of partial blobs: legs, an upper body)."""
        motion = track.motion
        x, P = motion.x.copy(), np.array(motion.P, dtype=np.float64)
        x[5] = 0.0
        P[5, :] = 0.0
        P[:, 5] = 0.0
        P[5, 5] = WALKER_VZ_VAR
        level = standing_level(track)
        if level is not None:
            x[2] = level[0]
            P[2, :] = 0.0
            P[:, 2] = 0.0
            P[2, 2] = self.config.measurement_noise_m**2
            track.extent_m[2] = level[1]
        motion.reset(x, P)

    def _decay(self, track: Track, dt: float, stamp_s: float) -> None:
        """Shrink the velocity of a track that got no update (after a grace of two frames).

        The decay is a mean-reverting (Ornstein-Uhlenbeck) velocity: the estimate shrinks by
        a = exp(-dt / velocity_decay_s) and, for the classes that search (people, ``unknown``),
        its variance relaxes towards the prior ``velocity_prior_mps``², so that a track picked
        up again learns its speed from the next observations at once instead of trusting the
        decayed (near zero) velocity. A chair's does not (``velocity_relax_static``): its gate
        would grow to ``gate_m`` within half a second unseen.
        """
        # At 4 Hz one frame (0.25 s) is longer than velocity_decay_grace_s: without the frame
        # term every single miss would decay and unsettle the velocity.
        grace = max(VELOCITY_DECAY_GRACE_S, DECAY_GRACE_FRAMES * dt)
        if stamp_s - track.last_update_s <= grace or dt <= 0:
            return
        relaxes = VELOCITY_RELAX_STATIC or track.search_class in SEARCH_CLASSES
        prior = VELOCITY_PRIOR_MPS**2 if relaxes else 0.0
        factor, scale, relax = _decay_terms(
            dt, VELOCITY_DECAY_S, prior, VERTICAL_NOISE_RATIO**2
        )
        track.motion.decay_velocity(factor, scale, relax)

    def _update(self, track: Track, m: Measurement, stamp_s: float) -> None:
        motion = track.motion
        walks = self._walks(track, m)
        center, extent = m.for_walker() if walks else (m.center_map_m, m.extent_map_m)
        if not track.velocity_initialised and track.hits == 1:
            dt = stamp_s - track.last_update_s
            if dt > MIN_VELOCITY_INIT_DT_S:
                # Two-point initialisation: v = (z2 - z1) / dt with its own covariance.
                v = (center - track.first_center) / dt
                r = self.config.measurement_noise_m**2
                var_v = 2.0 * r / dt**2 + (self._accel_noise(m.class_name) * dt) ** 2
                motion.reset(np.r_[center, v], np.diag([r, r, r, var_v, var_v, var_v]))
                track.velocity_initialised = True
                if track.trajectory:  # the first row gets the velocity it could not know yet
                    track.trajectory[0][ROW_VELOCITY] = v.tolist()
                    track.covariances[0] = np.array(motion.P, dtype=np.float64)
            else:
                motion.update(center)
        else:
            motion.update(center)
        track.hits += 1
        track.last_update_s = stamp_s
        track.unseen_in_view_s = 0.0
        track.extent_m = (1.0 - EXTENT_GAIN) * track.extent_m + EXTENT_GAIN * extent
        track.seen.add(*m.corners(), m.class_name != UNKNOWN, m.viewpoint_map_m, m.top_hidden,
                       m.bottom_hidden, m.class_name)
        if walks:
            _record_standing(track, m)
            self._hold_level(track)
        self._vote(track, m)
        self._confirm(track)

    def _confirm(self, track: Track, closing: bool = False) -> None:
        """Confirm a tentative track whose evidence is enough; withdraw a confirmed one whose
        evidence no longer holds (``unknown_evidence_held``: listed in ``withdrawn``)."""
        if not track.confirmed:
            track.confirmed = not closing and self._evidence_enough(track)
        elif UNKNOWN_EVIDENCE_HELD and not self._evidence_enough(track, closing):
            track.confirmed = False
            self.withdrawn.append(track.uuid)

    def _evidence_enough(self, track: Track, closing: bool = False) -> bool:
        """Whether a track may be an instance: ``confirm_hits`` observations, and, unless
        detections named it in ``min_class_share`` of its observations or gave it its class
        (``unknown_evidence_held``; else: named it ``min_class_observations`` times),
        ``unknown_confirm_whole`` whole ones over ``unknown_min_span_s``, at least
        ``unknown_min_whole_share`` of those that could tell. A track ``closing`` without a
        class that detections named most of the time must have lasted ``unknown_min_span_s``
        (while it lives, its class may still come: a person is named from its first view)."""
        cfg = self.config
        if track.hits < cfg.confirm_hits:
            return False
        if cfg.unknown_confirm_whole <= 0:
            return True
        named = sum(n for k, n in track.class_counts.items() if k != UNKNOWN)
        if UNKNOWN_EVIDENCE_HELD:
            if named_object(track):
                return True  # detections gave it a class (its full views may refuse that class)
            lasted = track.last_update_s - track.first_seen_s >= UNKNOWN_MIN_SPAN_S
            if named >= cfg.min_class_share * track.hits and (lasted or not closing):
                return True  # detections name it most of the time
        elif named >= cfg.min_class_observations or named >= cfg.min_class_share * track.hits:
            return True  # detections name it (often, or most of the time)
        stamps = track.whole_stamps_s
        return (
            len(stamps) >= cfg.unknown_confirm_whole
            and stamps[-1] - stamps[0] >= UNKNOWN_MIN_SPAN_S
            and len(stamps) >= UNKNOWN_MIN_WHOLE_SHARE * (track.hits - track.unsure_views)
        )

    def _vote(self, track: Track, m: Measurement) -> None:
        record(track, m, self.config.unknown_vote_weight)
        track.score_sum += m.score
        if m.detection_index is not None:
            stamp = round(track.last_update_s, STAMP_DECIMALS)
            track.named_at[stamp] = NamedBlob(m.detection_index, *m.corners(), m.detection_xyxy_px)
        track.unsure_views += m.whole is None
        if m.whole:
            track.whole_stamps_s.append(track.last_update_s)
            was, now = track.whole_footprint_m, np.array(m.extent_map_m[:2], float)
            track.whole_footprint_m = now if was is None else was + EXTENT_GAIN * (now - was)
        track.max_size_m = max(track.max_size_m, _size_m(m.extent_map_m))
        track.observation_uuids.append(m.observation_uuid)
        if m.appearance is not None and m.class_name in self.config.walker_classes:
            track.appearance = m.appearance if track.appearance is None else track.appearance + m.appearance
        track.trajectory.append([track.last_update_s, *track.position.tolist(), *track.velocity.tolist()])
        note_travel(track, self.config)
        q = self._accel_noise(track.class_name) ** 2
        track.covariances.append(np.array(track.motion.P, dtype=np.float64))
        track.noises.append((q, self._vertical_noise(track, q)))

    # --- association ------------------------------------------------------------------------
    def _gate(self, track: Track, stamp_s: float, variance_m2: float | None = None) -> tuple[float, float]:
        """(base gate, gate): the gate is the base widened while a moving track searches.
        ``variance_m2``: the largest eigenvalue of the track's position covariance (computed
        when not given)."""
        cfg = self.config
        dt = stamp_s - track.last_update_s
        base, gate = self._own_gate(track, dt, variance_m2)
        prior = self.priors(track.class_name)
        if cfg.use_learned_priors and prior.cu_mps is not None and 0 < dt < 1.0:
            # The paper rejects pairs beyond c_u · dt: a bound on the gate, never a widening
            # (a bottle's c_u comes from its noisiest rows; as a gate it joined two bottles).
            learned = float(prior.cu_mps) * dt + GATE_MARGIN_M
            return min(base, learned), min(gate, learned)
        return base, gate

    def _own_gate(self, track: Track, dt: float, variance_m2: float | None) -> tuple[float, float]:
        """(base gate, gate) from the track's filter and search state alone."""
        cfg = self.config
        searching = track.search_class in SEARCH_CLASSES and was_moving(track, cfg)
        unseen_s = max(dt - VELOCITY_DECAY_GRACE_S, 0.0) if searching else 0.0
        # The filter's own uncertainty: a settled track (a chair) gets a tight gate, a young
        # or fast-changing one up to gate_m.
        if variance_m2 is None:
            variance_m2 = float(np.linalg.eigvalsh(track.motion.P[:3, :3]).max())
        sigma = math.sqrt(variance_m2 + cfg.measurement_noise_m**2)
        base = min(max(GATE_SIGMAS * sigma, MIN_GATE_M), cfg.gate_m)
        return base, min(base + SEARCH_SPEED_MPS * unseen_s, MAX_GATE_M)

    def _settled(self, track: Track) -> bool:
        """Whether a track stood still long enough to be known where it is (``settled_hits``)."""
        cfg = self.config
        if SETTLED_HITS <= 0 or track.hits < SETTLED_HITS or track.class_name in cfg.walker_classes:
            return False
        if track.class_name != UNKNOWN:  # where its blobs were, not where partial views move its filter
            return is_static(track, cfg)
        return not was_moving(track, cfg) and math.hypot(*track.velocity[:2]) <= MOVING_SPEED_MPS

    def associate(self, measurements: Sequence[Measurement], stamp_s: float) -> list[tuple[int, int]]:
        """(track index, measurement index) pairs of the gated assignment (``association``)."""
        if not self.tracks or not measurements:
            return []
        pred = np.array([t.position for t in self.tracks])
        obs = np.array([m.center_map_m for m in measurements])
        cost = np.linalg.norm(pred[:, None, :] - obs[None, :, :], axis=2)
        settled = [self._settled(t) for t in self.tracks]
        for k in np.flatnonzero(settled):  # a filter that left the box of its blobs: the box's middle
            seen, margin = self.tracks[k].seen.corners(), SETTLED_OVERLAP_M
            if seen is not None and not np.all((seen[0] - margin <= pred[k]) & (pred[k] <= seen[1] + margin)):
                cost[k] = np.linalg.norm((seen[0] + seen[1]) / 2.0 - obs, axis=1)
        walking = np.array([self._walks(t) for t in self.tracks])
        if walking.any():  # a walker's distance to a blob's box as a walker's
            obs_walker = np.array([m.for_walker()[0] for m in measurements])
            cost[walking] = np.linalg.norm(pred[walking][:, None, :] - obs_walker[None, :, :], axis=2)
        # The filters' own uncertainty, all tracks in one eigenvalue call.
        P = np.array([t.motion.P[:3, :3] for t in self.tracks])
        variances = np.linalg.eigvalsh(P).max(axis=1)
        gates = np.array(
            [self._gate(t, stamp_s, float(v)) for t, v in zip(self.tracks, variances, strict=True)]
        ).reshape(-1, 2)
        allowed = cost <= gates[:, 1:2]
        searched = cost > gates[:, 0:1]
        cfg = self.config
        # lost: more than one frame missed (picked up again after one miss, the gap is 2 frames)
        grace = max(VELOCITY_DECAY_GRACE_S, LOST_AFTER_FRAMES * self._frame_dt_s)
        classes = np.array([m.class_name for m in measurements], dtype=object)
        unknown = classes == UNKNOWN
        sizes = np.array([_size_m(m.extent_map_m) for m in measurements])
        extents = np.array([m.extent_map_m for m in measurements])
        half_extents = extents / 2.0
        footprints = np.hypot(extents[:, 0], extents[:, 1])  # diagonal seen from above
        for i, t in enumerate(self.tracks):
            cls = t.class_name
            if settled[i]:
                # where its blobs were (``SeenBox``), not where a drifting filter puts it
                lo, hi = t.seen.corners() or (t.position - t.extent_m / 2.0, t.position + t.extent_m / 2.0)
                near = np.all(obs - half_extents <= hi + SETTLED_OVERLAP_M, axis=1)
                allowed[i] &= near & np.all(obs + half_extents >= lo - SETTLED_OVERLAP_M, axis=1)
            if cls != UNKNOWN:  # two different known classes cost more; unknown is neutral
                cost[i, ~unknown & (classes != cls)] += CLASS_MISMATCH_M
            if cls in cfg.walker_classes:
                allowed[i] &= sizes >= WALKER_MIN_SIZE_RATIO * t.max_size_m
            if cls in SEARCH_SAME_CLASS and stamp_s - t.last_update_s > grace:
                # Lost and searching: another class only when it is an unmatched blob as big as
                # the person (the person cut by the border).
                person_sized = unknown & (sizes >= SEARCH_MIN_SIZE_RATIO * t.max_size_m)
                person_sized &= footprints <= SEARCH_MAX_FOOTPRINT_M
                person_sized &= stamp_s - t.last_update_s <= SEARCH_UNKNOWN_MAX_S
                # past that, also inside the base gate its filter's uncertainty grew to
                judged = searched[i] | (stamp_s - t.last_update_s > SEARCH_UNKNOWN_MAX_S)
                allowed[i] &= ~(judged & (classes != cls) & ~person_sized)
        return self._assign(cost, allowed)

    # --- one step ---------------------------------------------------------------------------
    def step(
        self,
        stamp_s: float,
        measurements: Sequence[Measurement],
        visible: Callable[[FloatArray], NDArray[np.bool_]] | None = None,
    ) -> tuple[list[Track], list[str | None]]:
        """Advance to ``stamp_s`` with this frame's measurements.

        ``visible(points_map (N, 3)) -> (N,) bool`` says which predicted centres the camera
        could see now (None: all). Returns the tracks that changed (updated, newly confirmed or
        closed) and, per measurement, the uuid of the track it joined (``None``: a new
        tentative track).
        """
        dt_frame = 0.0 if self.last_stamp_s is None else max(stamp_s - self.last_stamp_s, 0.0)
        self.last_stamp_s = stamp_s
        self._frame_dt_s = dt_frame
        self.withdrawn = []
        for t in self.tracks:
            self._predict(t, stamp_s)
        pairs = self.associate(measurements, stamp_s)
        changed: list[Track] = []
        joined: list[str | None] = [None] * len(measurements)
        updated = set()
        for ti, mi in pairs:
            track = self.tracks[ti]
            self._update(track, measurements[mi], stamp_s)
            joined[mi] = track.uuid
            updated.add(ti)
            if track.confirmed:
                changed.append(track)
        unseen = [i for i in range(len(self.tracks)) if i not in updated]
        if unseen:
            seen_now = (
                visible(np.array([self.tracks[i].position for i in unseen]))
                if visible is not None
                else np.ones(len(unseen), dtype=bool)
            )
            cfg = self.config
            for i, in_view in zip(unseen, seen_now, strict=True):
                track = self.tracks[i]
                self._decay(track, dt_frame, stamp_s)
                if in_view:
                    track.unseen_in_view_s += dt_frame
                limit, lost = (
                    (cfg.max_age_s, LOST_MAX_S) if track.confirmed
                    else (TENTATIVE_MAX_AGE_S, TENTATIVE_LOST_MAX_S)
                )
                if track.unseen_in_view_s > limit or stamp_s - track.last_update_s > lost:
                    track.closed = True
                    self._confirm(track, closing=True)
                    if track.confirmed:
                        self._close(track)
                        self._retire(track)
                        changed.append(track)
        self.tracks = [t for t in self.tracks if not t.closed]
        for j, m in enumerate(measurements):
            if joined[j] is None:
                self.tracks.append(self._birth(m, stamp_s))
        aliases = self._stitch(stamp_s) if self.config.stitch else {}
        if aliases:
            joined = [aliases[u].uuid if u in aliases else u for u in joined]
            changed = [aliases.get(t.uuid, t) for t in changed]
            changed.extend(aliases.values())
            changed = list({id(t): t for t in changed}.values())
        return changed, joined

    def _stitch(self, stamp_s: float) -> dict[str, Track]:
        """Offer each newly confirmed track, one whose (provisional) class changed and a walker
        whose hits doubled to ``stitch.find_target``; absorbed ones leave the live tracks (a
        revived closed one takes their place) and are listed in ``absorbed``. Returns new uuid -> target."""
        self.absorbed = []
        cfg = self.config
        fresh = [
            t for t in self.tracks if t.confirmed and due(t, cfg.walker_classes, STITCH_STATIC_AGAIN)
        ]
        if not fresh:
            return {}
        self.dormant = [t for t in self.dormant if gap_ok(t, stamp_s, cfg)]
        aliases: dict[str, Track] = {}

        def moving(track: Track) -> bool:
            return not is_static(track, cfg)

        def together(a: Track, b: Track) -> bool:
            return static_together(a, b, cfg, lambda t: was_moving(t, cfg))

        pair = together if STITCH_STATIC_AGAIN else None
        for new in fresh:
            if new.uuid in aliases:  # folded into an older track earlier in this loop
                continue
            name = provisional_class(new)
            if name != new.stitch_class or new.hits >= 2 * new.stitch_hits:
                new.stitch_hits = new.hits  # an offer on growth keeps the doubling schedule
            new.stitch_class, new.stitch_area_m2 = name, footprint_m2(new)
            live = [t for t in self.tracks if t.uuid not in aliases]
            found = find_target(new, [*live, *self.dormant], cfg, moving, pair)
            if found is None and pair is not None:
                newer = newer_match(new, [*live, *self.dormant], cfg, moving, pair)
                if newer is not None:  # the older one asked: the newer folds into it
                    fold(new, newer)
                    self._absorbed_by(newer, new, aliases)
                    (self.dormant if newer in self.dormant else self.tracks).remove(newer)
                continue
            if found is None:
                continue
            old, kind = found
            if kind == REVISIT and pair is not None:
                fold(old, new)
            else:
                absorb(old, new, kind, stale_rows(new, old, cfg) if kind == RESUME else 0)
            self._absorbed_by(new, old, aliases)
            index = self.tracks.index(new)
            if kind != DUPLICATE and old in self.dormant:
                self.dormant.remove(old)
                self.tracks[index] = old
            else:
                del self.tracks[index]
        return aliases

    def _absorbed_by(self, gone: Track, target: Track, aliases: dict[str, Track]) -> None:
        """List ``gone`` as absorbed into ``target``, and point the tracks absorbed earlier into
        ``gone`` to ``target`` too."""
        self.absorbed.append(gone.uuid)
        aliases[gone.uuid] = target
        for uuid, was in aliases.items():
            if was is gone:
                aliases[uuid] = target

    def _retire(self, track: Track) -> None:
        """Keep a closed confirmed track for stitching: a static one (it stays where it is) or
        a walker (``stitch.gap_ok`` drops it later)."""
        if not self.config.stitch:
            return
        if STITCH_STATIC_AGAIN or track.class_name in self.config.walker_classes or is_static(
            track, self.config
        ):
            self.dormant.append(track)

    def _close(self, track: Track) -> None:
        if SMOOTH_CLOSED_TRACKS:
            smooth_trajectory(track)
        level = standing_level(track)
        if WALKER_LEVEL and track.class_name in self.config.walker_classes and level is not None:
            for row in track.trajectory:  # a walker stood on the floor all along
                row[3], row[6] = level[0], 0.0
        track.covariances, track.noises = [], []

    def _birth(self, m: Measurement, stamp_s: float) -> Track:
        walks = WALKER_LEVEL and m.class_name in self.config.walker_classes
        center, extent = m.for_walker() if walks else (m.center_map_m, m.extent_map_m)
        track = Track(
            uuid=new_uuid(),
            motion=make_motion_model(self.config.motion_model, center, self.config.measurement_noise_m),
            first_seen_s=stamp_s,
            last_update_s=stamp_s,
            last_time_s=stamp_s,
            extent_m=np.asarray(extent, dtype=np.float64).copy(),
            first_center=np.asarray(center, dtype=np.float64).copy(),
            min_class_observations=self.config.min_class_observations,
            min_class_share=self.config.min_class_share,
            size_tolerance=CLASS_SIZE_TOLERANCE if self.config.class_sizes else None,
            refused_min_views=self.config.refused_min_views,
        )
        track.seen.add(*m.corners(), m.class_name != UNKNOWN, m.viewpoint_map_m, m.top_hidden,
                       m.bottom_hidden, m.class_name)
        if walks:
            _record_standing(track, m)
            self._hold_level(track)
        self._vote(track, m)
        track.confirmed = self._evidence_enough(track)
        return track

    def close_all(self) -> list[Track]:
        """Close every live track (end of the log); returns the confirmed ones (``withdrawn``:
        those whose evidence failed on closing)."""
        out = []
        self.withdrawn = []
        for t in self.tracks:
            t.closed = True
            self._confirm(t, closing=True)
            if t.confirmed:
                self._close(t)
                out.append(t)
        self.tracks = []
        self.dormant = []
        return out
