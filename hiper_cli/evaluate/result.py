"""One result object for every measurement of perception against ground truth.

``Evaluation`` holds a scorer's figures (``figures``: exactly what it computed, the ``--json``
of the command that printed it) and the same figures sorted into six sections, so that a
reader finds a kind of figure in one place whichever command measured it:

- ``background``: Table II (surfaces: semantic and static precision, distance, coverage);
- ``foreground``: Table III counts (instances, TP / FP per class, precision, unknowns, switches);
- ``speed``: how fast people were seen to move, beside the truth;
- ``localisation``: centre errors in metres;
- ``recall``: what of the truth was found;
- ``timing``: frames and seconds per frame of the perception that was scored.

Two scorers feed it: ``scene`` scores instances (a knowledge base, an export) the way the
worlds' reference scorer does; ``perception`` scores an in-memory perception run per
observation against the per-pixel truth (the paper's Table III). A section key that a scorer
does not compute is absent, never invented.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["SECTIONS", "Evaluation", "session_timing"]

SECTIONS = ("background", "foreground", "speed", "localisation", "recall", "timing")

# per scorer: section -> the keys of its figures that belong there (the rest: foreground)
_PERCEPTION_KEYS: dict[str, tuple[str, ...]] = {
    "speed": ("people_dynamic_ratio", "people_speed_mps", "people_speed_ci_mps", "moving_people_speed_mps",
              "moving_people_true_speed_mps", "moving_people_speed_error_mps"),
    "localisation": ("localisation_classified_m", "localisation_visible_m", "localisation_visible_median_m",
                     "localisation_visible_xy_m", "localisation_visible_xy_median_m",
                     "localisation_box_centre_m"),
    "recall": ("truth_instances_seen",),
    "timing": ("frames", "detect_time_s", "frames_per_s", "foreground_frames_per_s", "points_mean",
               "points_after_background_mean"),
}
_SCENE_FOREGROUND_KEYS: dict[str, tuple[str, ...]] = {
    "speed": ("walkers_matched", "walker_speed_mean_mps", "walker_speed_error_mps"),
    "localisation": ("centre_error_mean_m", "centre_error_median_m"),
    "recall": ("fn_observed", "matched_truth_ids"),
}


def _split(figures: Mapping[str, Any], keys: dict[str, tuple[str, ...]]) -> dict[str, dict[str, Any]]:
    placed = {k for names in keys.values() for k in names}
    out = {section: {k: figures[k] for k in names if k in figures} for section, names in keys.items()}
    out["foreground"] = {k: v for k, v in figures.items() if k not in placed}
    return out


def session_timing(sessions: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Frames and wall seconds of the finished perceive sessions (``started_s`` to ``ended_s``,
    knowledge base writes included) and frames per second over them."""
    done = [s for s in sessions if s.get("ended_s") is not None and s.get("started_s") is not None]
    frames = sum(int(s.get("frames") or 0) for s in done)
    seconds = sum(float(s["ended_s"]) - float(s["started_s"]) for s in done)
    return {"sessions": len(sessions), "frames": frames, "seconds": seconds,
            "frames_per_s": frames / seconds if seconds > 0 else None}


@dataclass(frozen=True)
class Evaluation:
    """Perception scored against a log's ground truth (see the module docstring).

    ``scored``: what was scored (``knowledge base``, ``export`` or ``perception run``);
    ``scorer``: ``scene`` or ``perception``; ``figures``: the scorer's own output.
    """

    log: str
    world: str
    scored: str
    scorer: str
    figures: dict[str, Any]
    background: dict[str, Any] | None
    foreground: dict[str, Any]
    speed: dict[str, Any]
    localisation: dict[str, Any]
    recall: dict[str, Any]
    timing: dict[str, Any]

    @classmethod
    def of_perception(cls, log: str, world: str, figures: dict[str, Any]) -> Evaluation:
        """From ``score_run``'s Table III figures of an in-memory perception run."""
        parts = _split(figures, _PERCEPTION_KEYS)
        return cls(log, world, "perception run", "perception", figures, None, parts["foreground"],
                   parts["speed"], parts["localisation"], parts["recall"], parts["timing"])

    @classmethod
    def of_scene(cls, log: str, scored: str, figures: dict[str, Any], truth_observed: int,
                 timing: dict[str, Any]) -> Evaluation:
        """From ``score_scene``'s figures; ``truth_observed``: the foreground truth objects the
        log shows (recall's denominator); ``timing``: ``session_timing`` of what was scored."""
        fg = figures["foreground"]
        parts = _split(fg, _SCENE_FOREGROUND_KEYS)
        found = truth_observed - int(fg["fn_observed"])
        recall = {"truth_observed": truth_observed, "truth_found": found,
                  "recall_observed": found / truth_observed if truth_observed else None, **parts["recall"]}
        if "detector_ceiling" in figures:
            recall["detector_ceiling"] = figures["detector_ceiling"]
        return cls(log, str(figures["world"]), scored, "scene", figures, figures["background"],
                   parts["foreground"], parts["speed"], parts["localisation"], recall, timing)

    def to_dict(self) -> dict[str, Any]:
        """The sections (the ``--json`` of ``hiper_cli.evaluate``'s callers that show them all)."""
        return {"log": self.log, "world": self.world, "scored": self.scored, "scorer": self.scorer,
                **{name: getattr(self, name) for name in SECTIONS}}
