"""The feedback of feature learning into perception, measured (the paper's C2 ablation).

Features (ODS, size, altitude) are learned from one ``hiper sim`` log's foreground run; a
second log of the same world (another seed) is then perceived with them as priors, with
each prior alone, and without any (C2). The simulated pictures and TV screens show people
that the truth detector reports as ``person`` (the paper's false-positive trap), so the
person false positives with and without the priors show what the feedback buys.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from hiper_cli.analyze.features import FeatureConfig, features_of_tracks
from hiper_cli.analyze.window import TimeWindow
from hiper_cli.evaluate import perceive_and_score
from hiper_cli.graph.columns import columns_of_instances
from hiper_cli.model import Analysis, World
from hiper_cli.perceive.logs.truth import load_truth

__all__ = ["SWITCHES", "evaluate_feedback", "learn_priors", "learned_priors"]

_OFF = {"use_learned_priors": False}
_ONLY = {
    "learned_gates": False,
    "learned_motion_noise": False,
    "learned_size": False,
    "learned_altitude": False,
}
SWITCHES: dict[str, dict[str, bool]] = {
    "without (C2)": _OFF,
    "all priors": {},
    "size only": _ONLY | {"learned_size": True},
    "altitude only": _ONLY | {"learned_altitude": True},
    "gates and motion noise only": _ONLY | {"learned_gates": True, "learned_motion_noise": True},
}


def learn_priors(world: World) -> tuple[list[Analysis], dict[str, Any]]:
    """The features (ODS, size, altitude) of a perceived world's foreground tracks, as the
    analyses the foreground stage reads back, and per class as ``--json`` shows them."""
    tracks = columns_of_instances(list(world.foreground.values()))
    classes = features_of_tracks(tracks, TimeWindow(), 0.0, FeatureConfig())
    now = time.time()
    lo = float(tracks.rows[:, 0].min(initial=0.0))
    hi = float(tracks.rows[:, 0].max(initial=0.0))
    analyses = [a for c in classes for a in c.analyses(lo, hi, now)]
    return analyses, {c.class_name: c.to_dict() for c in classes}


def learned_priors(
    log_path: str | Path, background: str = "truth", **options: Any
) -> tuple[list[Analysis], dict[str, Any]]:
    """Perceive ``log_path`` without priors and learn the features of its instances."""
    done = perceive_and_score(log_path, background=background, **{**options, **_OFF})
    return learn_priors(done.run.world)


def _summary(scored: dict[str, Any]) -> dict[str, Any]:
    person = scored["classification"].get("person", {"tp": 0, "fp": 0})
    return {
        "person_tp": person["tp"],
        "person_fp": person["fp"],
        "tp": scored["tp"],
        "fp": scored["fp"],
        "fp_share": scored["fp_share"],
        "unknown_instances": scored["unknown_instances"],
        "identity_switches": scored["identity_switches"],
        "moving_people_speed_error_mps": scored["moving_people_speed_error_mps"],
    }


def evaluate_feedback(
    log_path: str | Path,
    learn_log: str | Path,
    *,
    detector: str = "truth",
    background: str = "truth",
    switches: dict[str, dict[str, bool]] | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Learn priors on ``learn_log``, perceive ``log_path`` under each switch setting and score
    it against its truth (see the module doc)."""
    opts = {"detector": detector, **options}
    priors, learned = learned_priors(learn_log, background, **opts)
    root = Path(log_path)
    truth = load_truth(root)
    runs = {}
    for name, flags in (switches or SWITCHES).items():
        settings = {**opts, **flags}
        done = perceive_and_score(root, background=background, priors=priors, truth=truth, **settings)
        runs[name] = _summary(done.evaluation.figures)
    return {
        "log": str(root),
        "learned_on": str(learn_log),
        "world": truth.world,
        "learned": learned,
        "runs": runs,
    }
