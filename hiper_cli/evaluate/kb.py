"""A knowledge base, or its JSON export, scored against a log's ground truth.

The instances are scored by ``scene.score_scene`` (the worlds' reference scorer's rules);
timing comes from the sessions that perceived them. An export keeps each background piece's
plane and, written with ``--observations``, the walkers' trajectories, so it scores as its
base does (without them a walker's distance falls back to its closest approach).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hiper_cli.errors import LogError
from hiper_cli.evaluate.result import Evaluation, session_timing
from hiper_cli.evaluate.scene import score_scene
from hiper_cli.evaluate.surfaces import load_surfaces
from hiper_cli.model import Instance

__all__ = ["evaluate_kb"]


def _read(source: Path, docs_dir: str | Path | None) -> tuple[str, list[Instance], list[dict[str, Any]]]:
    if source.is_file() and source.suffix.lower() == ".json":
        from hiper_cli.graph.exchange import read_export_instances

        instances, sessions = read_export_instances(source)
        return "export", instances, sessions
    from hiper_cli.graph import open_kb_for_reading

    with open_kb_for_reading(str(source), docs_dir=docs_dir) as knowledge:
        return "knowledge base", knowledge.instances(), knowledge.session_records()


def evaluate_kb(
    source: str | Path,
    log: str | Path,
    *,
    docs_dir: str | Path | None = None,
    ceiling: str | None = None,
) -> Evaluation:
    """Score the instances of ``source`` (a knowledge base, or a ``.json`` file written by
    ``hiper export --format json``) against ``log``'s ground truth (``gt/instances.json`` and
    ``gt/surface_points.npz``). ``ceiling``: also run this detector over the log and put
    hiper's recall of the clearly seen, nameable objects beside the detector's own."""
    from hiper_cli.perceive.logs.world_truth import load_world_truth

    root = Path(log)
    if not (root / "gt" / "instances.json").exists() and (root / "gt" / "world.json").exists():
        raise LogError(f"{root / 'gt' / 'instances.json'}: not found; this hiper sim log was made before "
                       "hiper sim wrote scene truth: make it again with hiper sim, or score it with "
                       "hiper eval background / hiper eval foreground")
    truth = load_world_truth(root)
    surfaces = load_surfaces(root)
    scored, instances, sessions = _read(Path(source), docs_dir)
    figures = score_scene(truth, surfaces, instances)
    if ceiling is not None:
        figures["detector_ceiling"] = _ceiling(root, ceiling, figures["foreground"]["matched_truth_ids"])
    observed = sum(t.layer == "foreground" and t.observed for t in truth.instances.values())
    return Evaluation.of_scene(str(root), scored, figures, observed, session_timing(sessions))


def _ceiling(log: Path, detector: str, matched_truth_ids: list[int]) -> dict[str, Any]:
    from hiper_cli.evaluate.detector import detector_ceiling, recall_beside_ceiling
    from hiper_cli.perceive.detect import make_detector
    from hiper_cli.perceive.logs import open_log

    result = detector_ceiling(log, open_log(log), make_detector(detector, log_path=log))
    return {**recall_beside_ceiling(result, matched_truth_ids), "detector": detector}
