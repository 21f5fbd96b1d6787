"""The class a track takes: a vote over the classes its observations were given.

Each observation votes for its class with its detection score (``unknown`` with
``unknown_vote_weight``), times ``CUT_VIEW_WEIGHT`` when the image's border cut its blob
(``Measurement.cut_by_border``): such a view shows a part of the object, and the detector's
word on a part, a name or a silence, is worth less. Over thirteen logs (clean, degraded, fresh
sims; right or wrong by the ground-truth object under the blob's pixels) the detector's names
were right in 0.73 of the views cut by the border and in 0.88 of the others; the weight is
that ratio (0.83), to one decimal. A known class wins only with minimum evidence:

- at least ``min_class_observations`` observations of it, and ``min_class_share`` of the
  known-class votes (two classes that keep swapping leave the track ``unknown``), outweighing
  ``unknown``;
- not too short for the class (``class_sizes``): some view that named it, with its blob seen
  whole, showed an object at least as long as the class's smallest instance;
- not refused: a view that shows the whole object, large enough to name (a *full view*,
  ``whole.in_full_view``), is one where a detector that gave the class would be expected to
  give it again, for the blob or inside its box. A class that none of the track's full views
  gave while ``refused_min_views`` of them named nothing, or while one of them
  (``CONTRADICTED_VIEWS``) named another class, is contradicted by the views, whatever the cut
  views said (a full view outweighs any number of partial ones, however often a detector
  repeats its word on a part): a
  detector that names a class only where the border cut the object or something hid a part
  was naming a part that looks like something else (a shelf's side taken for a chair's back; a
  walker's shoulders taken for a refrigerator while cut, ``person`` in full view). A full view
  that names nothing is weak evidence (detectors name true objects in as few as a quarter of
  their full views: a patient in a hospital bed, 29 of 106), one that names another class is
  strong.

The class an instance shows (``shown_class``) asks more: the track's class must outweigh the
``unknown`` votes ``SUPPORT_MARGIN`` times over. The views that saw the object and named
nothing are evidence too, and a class the detector gave in a few views among many silent ones
(a person's shoulders called ``refrigerator`` in 7 of 24 views, a couch called ``bed`` in 55
of 176, a desk called ``bench`` in 5 of 21) is too weakly supported to name the object. The
tracker keeps the class as its working hypothesis (how it associates and moves the track, its
box), so the object stays where it was found, ``unknown``.

Two rates (``keyframes.py``): a keyframe's closer look sees small and distant things that the
every-frame look cannot name, whose ``unknown`` from every frame would outvote any name. The
observations a closer look saw whole carry the class it gave them (``closer_class``), which
counts in a vote of its own: a known class named in at least ``CLOSER_MIN_LOOKS`` of them and in
``min_class_share`` of them all (each look one vote: the closer look resolves the thing, so its
``unknown`` counts as much as a name), not too short for the class. A track the every-frame vote
leaves ``unknown`` takes that vote's winner; the every-frame vote never sees the closer look.

A focused look (``focus.py``) crops the image around a track the every-frame detector named a
class the vote does not show (``is_question``) and runs the detector on the crop: the object at
several times the pixels, whole, in the middle. Each focused look counts once in a vote of its
own (``record_focus``, ``unknown`` for a crop that named nothing on the object): the track's
every-frame hypothesis is named when ``FOCUS_MIN_LOOKS`` focused looks gave it too and it has
``FOCUS_SHARE`` of them (two looks at different scales agreeing on the object). A class only the
crops gave names nothing: a crop, enlarged, sees things in texture (a cart as a chair).

The tallies live on the ``Track`` (``class_votes``, ``class_counts``, ...); these functions
record, merge and read them. ``Track._class_name`` caches the winner; ``record`` and
``absorb_votes`` clear it.
"""

from __future__ import annotations

from typing import Protocol

from hiper_cli.perceive.foreground.plausible import min_longest_m

__all__ = [
    "UNKNOWN", "absorb_votes", "is_question", "named_object", "record", "record_focus", "search_class",
    "shown_class", "winner",
]

UNKNOWN = "unknown"
CONTRADICTED_VIEWS: int = 1
"""Full views that named another class and none this one refuse a class (``_refused``). Over
thirteen logs one track had a detector's class that no full view gave and a full view that gave
another: a walker called ``refrigerator`` in 54 views cut by the border, ``person`` in 1 of its
3 full views."""
CUT_VIEW_WEIGHT: float = 0.8
"""What a view whose blob the image's border cut counts in the vote, against 1 for a view that
shows the blob inside the image: the detector's names were right in 0.73 of such views and in
0.88 of the others (module docstring). Replayed over the thirteen logs' tracks, 0.8 leaves every
true positive and drops a holder called ``oven``; 0.75 and below name office 62's couch ``bed``."""
SUPPORT_MARGIN: float = 1.5
"""A class names an instance only when its score-weighted votes outweigh the ``unknown`` votes
(views that saw the object and named nothing) this many times over (``shown_class``; 1: as
the vote)."""


class Vote(Protocol):
    """What one observation tells the vote (a ``track.Measurement``)."""

    @property
    def class_name(self) -> str: ...
    @property
    def score(self) -> float: ...
    @property
    def longest_m(self) -> float | None: ...
    @property
    def full_view(self) -> bool: ...
    @property
    def named_within(self) -> frozenset[str]: ...
    @property
    def detection_index(self) -> int | None: ...
    @property
    def closer_class(self) -> str | None: ...
    @property
    def cut_by_border(self) -> bool: ...


class Track(Protocol):
    """The tallies of a track the vote keeps and reads (a ``track.Track``): typed here, so that
    the vote needs nothing of the tracker's."""

    class_votes: dict[str, float]
    class_counts: dict[str, int]
    class_longest_m: dict[str, float]
    full_views: int
    full_named: dict[str, int]
    detected_classes: set[str]
    closer_counts: dict[str, int]
    focus_counts: dict[str, int]
    min_class_observations: int
    min_class_share: float
    size_tolerance: float | None
    refused_min_views: int
    _class_name: str | None

    @property
    def class_name(self) -> str: ...
MIN_VOTE_WEIGHT = 1e-3  # a known-class detection of score 0 still counts a little
CLOSER_MIN_LOOKS = 3
"""Closer looks (keyframes, ``keyframes.py``) that named a class before it wins the closer look's
vote: keyframes are seconds apart, so three are three views, where frames at 30 Hz are one."""
FOCUS_MIN_LOOKS = 3
"""Focused looks (``focus.py``) that gave the every-frame hypothesis before it is named."""
FOCUS_SHARE = 0.5
"""... and their share of the track's focused looks, silent ones included."""


def record(track: Track, m: Vote, unknown_vote_weight: float) -> None:
    """Count ``m``'s class in the track's tallies."""
    weight = unknown_vote_weight if m.class_name == UNKNOWN else max(m.score, MIN_VOTE_WEIGHT)
    if m.cut_by_border:
        weight *= CUT_VIEW_WEIGHT
    track.class_votes[m.class_name] = track.class_votes.get(m.class_name, 0.0) + weight
    track.class_counts[m.class_name] = track.class_counts.get(m.class_name, 0) + 1
    if m.closer_class is not None:
        track.closer_counts[m.closer_class] = track.closer_counts.get(m.closer_class, 0) + 1
    if m.longest_m is not None and m.class_name != UNKNOWN:
        seen = track.class_longest_m.get(m.class_name, 0.0)
        track.class_longest_m[m.class_name] = max(seen, m.longest_m)
    if m.full_view:
        track.full_views += 1
        for cls in (m.named_within | {m.class_name}) - {UNKNOWN}:
            track.full_named[cls] = track.full_named.get(cls, 0) + 1
    if m.detection_index is not None:
        track.detected_classes.add(m.class_name)
    track._class_name = None


def absorb_votes(old: Track, new: Track) -> None:
    """Add ``new``'s tallies to ``old``'s (``stitch.absorb``: two tracks of one object)."""
    for cls, votes in new.class_votes.items():
        old.class_votes[cls] = old.class_votes.get(cls, 0.0) + votes
    for cls, count in new.class_counts.items():
        old.class_counts[cls] = old.class_counts.get(cls, 0) + count
    for cls, longest in new.class_longest_m.items():
        old.class_longest_m[cls] = max(old.class_longest_m.get(cls, 0.0), longest)
    old.full_views += new.full_views
    for cls, count in new.full_named.items():
        old.full_named[cls] = old.full_named.get(cls, 0) + count
    old.detected_classes |= new.detected_classes
    for cls, count in new.closer_counts.items():
        old.closer_counts[cls] = old.closer_counts.get(cls, 0) + count
    for cls, count in new.focus_counts.items():
        old.focus_counts[cls] = old.focus_counts.get(cls, 0) + count
    old._class_name = None


def record_focus(track: Track, class_name: str) -> None:
    """Count a focused look's answer on the track (``focus.py``; ``unknown``: it named nothing)."""
    track.focus_counts[class_name] = track.focus_counts.get(class_name, 0) + 1
    track._class_name = None


def is_question(track: Track) -> bool:
    """Whether a focused look could decide the track: the every-frame detector named it a class
    (``search_class``) that its instance does not show."""
    return search_class(track) != UNKNOWN and shown_class(track) == UNKNOWN


def winner(track: Track, judged: bool = True) -> str:
    """The vote's winner, or ``unknown`` without the evidence (see the module docstring), the
    closer looks' winner when every frame's vote has none; ``judged`` False: without the full
    views' judgement (``refused_min_views``): whether detections saw an object there
    (``named_object``)."""
    known = {k: v for k, v in track.class_votes.items() if k != UNKNOWN}
    eligible = [
        k for k in sorted(known)
        if track.class_counts.get(k, 0) >= track.min_class_observations and _long_enough(track, k)
        and not (judged and _refused(track, k))
    ]
    if not eligible:
        return _closer_winner(track, judged)
    best = max(eligible, key=lambda k: known[k])
    if known[best] < track.min_class_share * sum(known.values()):
        return _closer_winner(track, judged)
    if track.class_votes.get(UNKNOWN, 0.0) > known[best]:
        return _closer_winner(track, judged)
    return best


def _closer_winner(track: Track, judged: bool = True) -> str:
    """The closer looks' winner (see the module docstring), or ``unknown``; a class the full
    views refused stays refused whichever look gave it (``judged``, as in ``winner``)."""
    known = {k: n for k, n in track.closer_counts.items() if k != UNKNOWN}
    if not known:
        return _focused_winner(track, judged)
    best = max(sorted(known), key=lambda k: known[k])
    looks = sum(track.closer_counts.values())
    if known[best] < max(CLOSER_MIN_LOOKS, track.min_class_share * looks) or not _long_enough(track, best):
        return _focused_winner(track, judged)
    if judged and _refused(track, best):
        return _focused_winner(track, judged)
    return best


def _focused_winner(track: Track, judged: bool = True) -> str:
    """The every-frame hypothesis when the focused looks confirm it (module docstring), else
    ``unknown``; a class the full views refused stays refused (``judged``)."""
    known = {k: n for k, n in track.focus_counts.items() if k != UNKNOWN}
    if not known:
        return UNKNOWN
    best = max(sorted(known), key=lambda k: known[k])
    looks = sum(track.focus_counts.values())
    if known[best] < max(FOCUS_MIN_LOOKS, FOCUS_SHARE * looks):
        return UNKNOWN
    if track.class_counts.get(best, 0) < track.min_class_observations or not _long_enough(track, best):
        return UNKNOWN
    if judged and _refused(track, best):
        return UNKNOWN
    return best


def shown_class(track: Track) -> str:
    """The class the track's instance shows: its class when its votes outweigh the ``unknown``
    ones ``SUPPORT_MARGIN`` times over or the closer looks chose it, else ``unknown`` (see the
    module docstring)."""
    name, votes = track.class_name, track.class_votes
    if name == UNKNOWN or votes.get(name, 0.0) >= SUPPORT_MARGIN * votes.get(UNKNOWN, 0.0):
        return name
    # a class the closer or focused looks chose was weighed against their own ``unknown`` looks
    return name if _closer_winner(track) == name else UNKNOWN


def named_object(track: Track) -> bool:
    """Whether detections named the track enough to give it a class, one its full views may
    have refused since: they tell what it is not, not that nothing is there (the track is an
    object, ``unknown``, as a walker named ``refrigerator`` still walks there)."""
    return track.class_name != UNKNOWN or winner(track, judged=False) != UNKNOWN


def search_class(track: Track) -> str:
    """The track's class, or while ``unknown`` the known class detections named most when they
    named it at least ``min_class_observations`` times (a class the vote turned down for its
    share, size or refusal still says what kind of thing it is)."""
    name = track.class_name
    if name != UNKNOWN:
        return name
    named = [k for k, n in track.class_counts.items() if k != UNKNOWN and n >= track.min_class_observations]
    return max(sorted(named), key=lambda k: track.class_votes[k]) if named else UNKNOWN


def _long_enough(track: Track, class_name: str) -> bool:
    """False when every view that named the track ``class_name`` with its blob seen whole
    showed an object shorter than the class's smallest instance (``class_sizes``)."""
    seen = track.class_longest_m.get(class_name)
    if track.size_tolerance is None or seen is None:
        return True
    return seen >= min_longest_m(class_name, track.size_tolerance)


def _refused(track: Track, class_name: str) -> bool:
    """Whether the track's full views contradict ``class_name``: none named it, and they are
    ``refused_min_views`` or ``CONTRADICTED_VIEWS`` named another class (0 views: off). A class
    found by its shape (a table top), not by a detector that could decline it, is not judged."""
    if track.refused_min_views <= 0 or class_name not in track.detected_classes:
        return False
    if track.full_named.get(class_name, 0) > 0:
        return False
    other = max((n for k, n in track.full_named.items() if k != class_name), default=0)
    return track.full_views >= track.refused_min_views or other >= CONTRADICTED_VIEWS
