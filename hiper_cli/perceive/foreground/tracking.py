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
from hiper_cli.perceive.foreground.class_vote import UNKNOWN, record
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.motion import MOTION_MODELS, make_motion_model
from hiper_cli.perceive.foreground.moving import is_static, note_travel, was_moving
from hiper_cli.perceive.foreground.same_object import (
    STAMP_DECIMALS,
    due,
    fold,
    footprint_m2,
    newer_match,
    static_together,
)
from hiper_cli.perceive.foreground.smoother import smooth_trajectory
from hiper_cli.perceive.foreground.split_parts import held_tables, last_box
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
            return max(float(prior.sigma_mps), MIN_PRIOR_SIGMA_MPS) / self.config.prior_accel_time_s
        if class_name in self.config.walker_classes:
            return self.config.walker_accel_noise_mps2
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
        if not self.config.walker_level:
            return False
        name = track.class_name
        if name == UNKNOWN and m is not None:
            name = m.class_name
        return name in self.config.walker_classes

    def _vertical_noise(self, track: Track, q: float) -> float:
        return 0.0 if self._walks(track) else q * self.config.vertical_noise_ratio**2

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
        grace = max(self.config.velocity_decay_grace_s, DECAY_GRACE_FRAMES * dt)
        if stamp_s - track.last_update_s <= grace or dt <= 0:
            return
        relaxes = self.config.velocity_relax_static or track.search_class in self.config.search_classes
        prior = self.config.velocity_prior_mps**2 if relaxes else 0.0
        factor, scale, relax = _decay_terms(
            dt, self.config.velocity_decay_s, prior, self.config.vertical_noise_ratio**2
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
        elif self.config.unknown_evidence_held and not self._evidence_enough(track, closing):
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
        if cfg.unknown_evidence_held:
            if track.class_name != UNKNOWN:
                return True  # detections gave it its class
            lasted = track.last_update_s - track.first_seen_s >= cfg.unknown_min_span_s
            if named >= cfg.min_class_share * track.hits and (lasted or not closing):
                return True  # detections name it most of the time
        elif named >= cfg.min_class_observations or named >= cfg.min_class_share * track.hits:
            return True  # detections name it (often, or most of the time)
        stamps = track.whole_stamps_s
        return (
            len(stamps) >= cfg.unknown_confirm_whole
            and stamps[-1] - stamps[0] >= cfg.unknown_min_span_s
            and len(stamps) >= cfg.unknown_min_whole_share * (track.hits - track.unsure_views)
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
            learned = float(prior.cu_mps) * dt + cfg.gate_margin_m
            return min(base, learned), min(gate, learned)
        return base, gate

    def _own_gate(self, track: Track, dt: float, variance_m2: float | None) -> tuple[float, float]:
        """(base gate, gate) from the track's filter and search state alone."""
        cfg = self.config
        searching = track.search_class in cfg.search_classes and was_moving(track, cfg)
        unseen_s = max(dt - cfg.velocity_decay_grace_s, 0.0) if searching else 0.0
        # The filter's own uncertainty: a settled track (a chair) gets a tight gate, a young
        # or fast-changing one up to gate_m.
        if variance_m2 is None:
            variance_m2 = float(np.linalg.eigvalsh(track.motion.P[:3, :3]).max())
        sigma = math.sqrt(variance_m2 + cfg.measurement_noise_m**2)
        base = min(max(cfg.gate_sigmas * sigma, cfg.min_gate_m), cfg.gate_m)
        return base, min(base + cfg.search_speed_mps * unseen_s, cfg.max_gate_m)

    def _settled(self, track: Track) -> bool:
        """Whether a track stood still long enough to be known where it is (``settled_hits``)."""
        cfg = self.config
        if cfg.settled_hits <= 0 or track.hits < cfg.settled_hits or track.class_name in cfg.walker_classes:
            return False
        if track.class_name != UNKNOWN:  # where its blobs were, not where partial views move its filter
            return is_static(track, cfg)
        return not was_moving(track, cfg) and math.hypot(*track.velocity[:2]) <= cfg.moving_speed_mps

    def associate(self, measurements: Sequence[Measurement], stamp_s: float) -> list[tuple[int, int]]:
        """(track index, measurement index) pairs of the gated assignment (``association``)."""
        if not self.tracks or not measurements:
            return []
        pred = np.array([t.position for t in self.tracks])
        obs = np.array([m.center_map_m for m in measurements])
        cost = np.linalg.norm(pred[:, None, :] - obs[None, :, :], axis=2)
        settled = [self._settled(t) for t in self.tracks]
        for k in np.flatnonzero(settled):  # a filter that left the box of its blobs: the box's middle
            seen, margin = self.tracks[k].seen.corners(), self.config.settled_overlap_m
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
        grace = max(cfg.velocity_decay_grace_s, LOST_AFTER_FRAMES * self._frame_dt_s)
        classes = np.array([m.class_name for m in measurements], dtype=object)
        unknown = classes == UNKNOWN
        sizes = np.array([_size_m(m.extent_map_m) for m in measurements])
        solid = np.array([m.solid for m in measurements], dtype=bool)
        extents = np.array([m.extent_map_m for m in measurements])
        half_extents = extents / 2.0
        footprints = np.hypot(extents[:, 0], extents[:, 1])  # diagonal seen from above
        for i, t in enumerate(self.tracks):
            cls = t.class_name
            if settled[i]:
                # where its blobs were (``SeenBox``), not where a drifting filter puts it
                lo, hi = t.seen.corners() or (t.position - t.extent_m / 2.0, t.position + t.extent_m / 2.0)
                near = np.all(obs - half_extents <= hi + cfg.settled_overlap_m, axis=1)
                allowed[i] &= near & np.all(obs + half_extents >= lo - cfg.settled_overlap_m, axis=1)
            if cls != UNKNOWN:  # two different known classes cost more; unknown is neutral
                cost[i, ~unknown & (classes != cls)] += cfg.class_mismatch_m
            if cls in cfg.walker_classes:
                allowed[i] &= (sizes >= cfg.walker_min_size_ratio * t.max_size_m) & solid
            if cls in cfg.search_same_class and stamp_s - t.last_update_s > grace:
                # Lost and searching: another class only when it is an unmatched blob as big as
                # the person (the person cut by the border).
                person_sized = unknown & (sizes >= cfg.search_min_size_ratio * t.max_size_m)
                person_sized &= footprints <= cfg.search_max_footprint_m
                person_sized &= stamp_s - t.last_update_s <= cfg.search_unknown_max_s
                # past that, also inside the base gate its filter's uncertainty grew to
                judged = searched[i] | (stamp_s - t.last_update_s > cfg.search_unknown_max_s)
                allowed[i] &= ~(judged & (classes != cls) & ~person_sized)
        cut = [m.cut_from_table_m for m in measurements]
        if any(box is not None for box in cut):  # not the unnamed track of the blob it was cut from
            allowed &= ~held_tables([last_box(t) for t in self.tracks], cut)
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
                    (cfg.max_age_s, cfg.lost_max_s) if track.confirmed
                    else (cfg.tentative_max_age_s, cfg.tentative_lost_max_s)
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
            t for t in self.tracks if t.confirmed and due(t, cfg.walker_classes, cfg.stitch_static_again)
        ]
        if not fresh:
            return {}
        self.dormant = [t for t in self.dormant if gap_ok(t, stamp_s, cfg)]
        aliases: dict[str, Track] = {}

        def moving(track: Track) -> bool:
            return not is_static(track, cfg)

        def together(a: Track, b: Track) -> bool:
            return static_together(a, b, cfg, lambda t: was_moving(t, cfg))

        pair = together if cfg.stitch_static_again else None
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
        if self.config.stitch_static_again or track.class_name in self.config.walker_classes or is_static(
            track, self.config
        ):
            self.dormant.append(track)

    def _close(self, track: Track) -> None:
        if self.config.smooth_closed_tracks:
            smooth_trajectory(track)
        level = standing_level(track)
        if self.config.walker_level and track.class_name in self.config.walker_classes and level is not None:
            for row in track.trajectory:  # a walker stood on the floor all along
                row[3], row[6] = level[0], 0.0
        track.covariances, track.noises = [], []

    def _birth(self, m: Measurement, stamp_s: float) -> Track:
        walks = self.config.walker_level and m.class_name in self.config.walker_classes
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
            size_tolerance=self.config.class_size_tolerance if self.config.class_sizes else None,
            refused_min_views=self.config.refused_min_views,
            refused_max_share=self.config.refused_max_share,
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
