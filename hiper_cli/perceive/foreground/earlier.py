"""This session's objects against the earlier sessions' (``reidentify.py``, ``vacated.py``).

At the end of a session each earlier session's object is found again (this session's static
instance overlaps it, or a walker was seen at the same times), moved (its place seen empty and
an instance of its class found elsewhere, in a place the earlier sessions did not see
occupied), vacated (its place seen empty, and no object found again there), or left as it was:
unseen is not removed.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from hiper_cli.model import Instance
from hiper_cli.perceive.foreground.reidentify import (
    REIDENTIFY_MOVED_M,
    cosighted_pairs,
    fold,
    fold_mover,
    moved_pairs,
    pairs,
    still_seen,
)
from hiper_cli.perceive.foreground.stitch import STITCH_DUPLICATE_M, STITCH_MIN_OVERLAP, STITCH_OVERLAP_M

__all__ = ["meet_earlier"]


def meet_earlier(
    own: dict[str, Instance], earlier_all: Mapping[str, Instance], static: set[str], *,
    stays: Callable[[Instance], bool], vacated: Mapping[str, float],
    occupied: Callable[[Instance], bool], walkers: tuple[str, ...], confirm_hits: int,
) -> tuple[list[Instance], list[str], dict[str, int]]:
    """The earlier sessions' instances (``earlier_all``: the world's foreground) that absorbed
    one of this session's (``own``, by uuid: the absorbed are deleted from it; ``static``: the
    uuids of its static ones) or a walker seen at the same times, or whose place this session
    saw empty (``vacated``: uuid -> stamp); the uuids absorbed; and how many were found again,
    moved and vacated. ``stays``: an object that stays where it was left; ``occupied``: whether
    the earlier sessions saw a new instance's place occupied."""
    earlier = {u: i for u, i in earlier_all.items() if u not in own and stays(i)}
    new = [i for u, i in own.items() if u in static and stays(i)]
    found = pairs(new, earlier.values(), min_share=STITCH_MIN_OVERLAP, max_gap_m=STITCH_OVERLAP_M)
    paired = {u for e, n in found for u in (e.uuid, n.uuid)}
    # seen empty now, or by an earlier session: gone from where it was
    gone = [i for u, i in earlier.items() if u not in paired and (u in vacated or "vacated_s" in i.data)]
    # what was present until now left in the gap before this session: not for a place the
    # earlier sessions saw occupied; one an earlier session already found gone may have gone
    # anywhere then
    free = [n for n in new if n.uuid not in paired and not occupied(n)]
    moved = moved_pairs([n for n in new if n.uuid not in paired],
                        [i for i in gone if "vacated_s" in i.data], max_m=REIDENTIFY_MOVED_M)
    taken = {u for e, n in moved for u in (e.uuid, n.uuid)}
    moved += moved_pairs([n for n in free if n.uuid not in taken],
                         [i for i in gone if "vacated_s" not in i.data], max_m=REIDENTIFY_MOVED_M)
    found += moved
    for old, absorbed in found:
        fold(old, absorbed)
        del own[absorbed.uuid]
    cosighted = cosighted_pairs(
        [i for i in own.values() if i.class_name in walkers],
        [i for u, i in earlier_all.items() if u not in own and i.class_name in walkers],
        max_m=STITCH_DUPLICATE_M, min_common=confirm_hits,
    )
    for old, absorbed in cosighted:
        fold_mover(old, absorbed)
        del own[absorbed.uuid]
    found += cosighted
    joined = {old.uuid for old, _ in found}
    left = [i for i in gone if i.uuid not in joined and "vacated_s" not in i.data]
    # seen empty by its old points, yet seen at its place (not by another object found again)
    there = still_seen(left, new, found_again=[n for _, n in found])
    marked = [i for i in left if i.uuid not in there]
    for inst in marked:
        # never before it was last seen (logs whose stamps all start at 0 overlap in time)
        inst.data["vacated_s"] = max(vacated[inst.uuid], inst.last_seen_s)
    earlier_joined = list({old.uuid: old for old, _ in found}.values())
    counts = {"found_again": len(earlier_joined), "moved": len(moved), "vacated": len(marked)}
    return earlier_joined + marked, [absorbed.uuid for _, absorbed in found], counts
