"""Table tops by the votes of their views: a top most views see standing on a solid block is none.

One view of a top tells little: from near, its near edge is the image's lower edge and the
camera cannot look under it (``under.py``: ``unknown``); a chair pushed under a table, or a
desk's front panel, shows a solid front from one side only. A bed, a counter or a box stack
shows it from every side that sees under its edge. ``TableVotes`` keeps every table top
observation's plane, merged like background instances (Algorithm 2's criteria), with the
number of its views that saw under it on legs and that saw a solid front. A top with more
solid views than legs views is no table: the table instances it matches are deleted and a
later table observation it matches is dropped, whatever that view saw.
"""

from __future__ import annotations

from hiper_cli.model import Instance
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.merge import (
    MapObservation,
    instance_matches,
    match_instances,
    merge_into,
    new_instance,
)
from hiper_cli.perceive.background.under import UnderEvidence

__all__ = ["TableVotes"]


class TableVotes:
    """Memory of the table tops seen, map frame, with their views' votes (solid, legs)."""

    def __init__(self, cfg: BackgroundConfig) -> None:
        self.cfg = cfg
        self.tops: dict[str, Instance] = {}
        self.votes: dict[str, tuple[int, int]] = {}  # top uuid: (solid views, legs views)

    def vote(self, mo: MapObservation, evidence: UnderEvidence) -> bool:
        """Count the view ``mo`` of a table top that saw ``evidence`` under its near edge;
        whether the top it belongs to is a table by the votes so far. (Merging sets the
        observation's instance uuid to the remembered top's; the world's merge, after this,
        sets it to the instance's.)"""
        found = match_instances(mo, list(self.tops.values()), self.cfg)
        prior = [self.votes.pop(t.uuid) for t in found]
        solid = int(evidence == "solid") + sum(v[0] for v in prior)
        legs = int(evidence == "legs") + sum(v[1] for v in prior)
        top = merge_into(found[0], found[1:], mo, self.cfg) if found else new_instance(mo, self.cfg)
        for dup in found[1:]:
            self.tops.pop(dup.uuid, None)
        self.tops[top.uuid] = top
        self.votes[top.uuid] = (solid, legs)
        return solid <= legs

    def settle(self, live: dict[str, Instance]) -> list[str]:
        """Remove from ``live`` the table instances that lie on a top with more solid views than
        legs views; returns their uuids."""
        solid = [self.tops[u] for u, (s, legs) in self.votes.items() if s > legs]
        failed = [
            uuid for uuid, inst in live.items()
            if inst.class_name == "table" and any(instance_matches(inst, top, self.cfg) for top in solid)
        ]
        for uuid in failed:
            del live[uuid]
        return failed

