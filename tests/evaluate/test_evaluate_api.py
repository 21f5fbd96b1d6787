"""``hiper_cli.evaluate``: one measuring API, one result object, whichever command asks."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import LogError
from hiper_cli.evaluate import SECTIONS, Evaluation, evaluate_foreground, evaluate_kb, perceive_and_score
from hiper_cli.evaluate.scene import score_scene
from hiper_cli.evaluate.surfaces import load_surfaces
from hiper_cli.graph import open_kb
from hiper_cli.perceive.logs.truth import load_truth
from tests import REPO_ROOT
from tests.evaluate.test_eval_scene import _instances, _write_gt

FIXTURE = REPO_ROOT / "fixtures" / "house_small"


@pytest.fixture()
def scored(tmp_path):
    """A tiny world's truth, a knowledge base holding its instances, and its JSON export."""
    log = tmp_path / "log"
    _write_gt(log)
    kb = tmp_path / "kb.hiper"
    with open_kb(kb) as knowledge:
        knowledge.put_documents([i.to_dict() for i in _instances()])
    export = tmp_path / "kb.json"
    result = CliRunner().invoke(app, ["export", str(export), "--kb", str(kb), "--observations"])
    assert result.exit_code == 0, result.output
    return log, kb, export


def test_a_kb_scores_as_the_scene_scorer_scores_its_instances(scored):
    log, kb, _ = scored
    ev = evaluate_kb(kb, log)
    assert ev.scored == "knowledge base" and ev.scorer == "scene"
    assert ev.figures == score_scene(load_truth(log), load_surfaces(log), _instances())


def test_an_export_scores_as_its_knowledge_base(scored):
    log, kb, export = scored
    assert evaluate_kb(export, log).figures == evaluate_kb(kb, log).figures
    assert evaluate_kb(export, log).scored == "export"


def test_the_sections_hold_the_figures(scored):
    log, kb, _ = scored
    ev = evaluate_kb(kb, log)
    assert set(ev.to_dict()) == {"log", "world", "scored", "scorer", *SECTIONS}
    assert ev.background is not None and ev.background["pieces"] == 2
    assert (ev.foreground["tp"], ev.foreground["fp"]) == (2, 2)
    # chair, shelf and walker are observed; the chair and the walker are found
    assert (ev.recall["truth_observed"], ev.recall["truth_found"]) == (3, 2)
    assert ev.recall["recall_observed"] == pytest.approx(2 / 3)
    assert ev.speed["walkers_matched"] == 1
    assert ev.localisation["centre_error_mean_m"] == pytest.approx(0.0707, abs=1e-3)
    assert ev.timing == {"sessions": 0, "frames": 0, "seconds": 0, "frames_per_s": None}


def test_eval_scene_takes_an_export(scored):
    log, kb, export = scored
    out = {}
    for source in (kb, export):
        result = CliRunner().invoke(app, ["eval", "scene", str(log), "--kb", str(source), "--json"])
        assert result.exit_code == 0, result.output
        out[source] = json.loads(result.output)
    assert out[kb] == out[export] == evaluate_kb(kb, log).figures


def test_a_sim_log_without_scene_truth_is_named(tmp_path):
    (tmp_path / "gt").mkdir()
    (tmp_path / "gt" / "world.json").write_text("{}")
    with pytest.raises(LogError, match=r"instances\.json: not found"):
        evaluate_kb(tmp_path / "kb.hiper", tmp_path)


def test_a_perception_run_puts_each_figure_in_one_section():
    done = perceive_and_score(FIXTURE, detector="truth", background="truth", max_frames=12)
    ev = done.evaluation
    assert isinstance(ev, Evaluation) and ev.scorer == "perception" and ev.background is None
    placed = [k for name in SECTIONS if name != "background" for k in getattr(ev, name)]
    assert sorted(placed) == sorted(ev.figures)
    assert ev.timing["frames"] == 12 and "localisation_classified_m" in ev.localisation
    assert ev.foreground["sum_i"] == len(done.run.world.foreground)


def test_the_table_iii_report_is_the_api_s_figures():
    """``hiper eval foreground`` scores through ``perceive_and_score``: the same counts."""
    report = evaluate_foreground(FIXTURE, detector="truth", ablation=False, background="truth", max_frames=12)
    again = perceive_and_score(FIXTURE, detector="truth", background_filter=True, background="truth",
                               max_frames=12).evaluation
    for key in ("classification", "tp", "fp", "sum_i", "sum_o", "identity_switches", "truth_instances_seen"):
        assert report.ours[key] == again.figures[key], key


def test_the_feedback_check_scores_through_the_api():
    """``hiper eval feedback`` perceives and scores with ``perceive_and_score``: its C2 row is
    the API's figures of the same run."""
    from hiper_cli.analyze.feedback import SWITCHES, evaluate_feedback

    report = evaluate_feedback(FIXTURE, FIXTURE, switches={"without (C2)": SWITCHES["without (C2)"]})
    row = report["runs"]["without (C2)"]
    done = perceive_and_score(FIXTURE, detector="truth", background="truth", use_learned_priors=False)
    ev = done.evaluation
    assert (row["tp"], row["fp"], row["unknown_instances"]) == (
        ev.foreground["tp"], ev.foreground["fp"], ev.foreground["unknown_instances"])
    assert row["person_fp"] == ev.foreground["classification"].get("person", {"fp": 0})["fp"]
    assert row["moving_people_speed_error_mps"] == ev.speed["moving_people_speed_error_mps"]


def test_eval_changes_names_a_folder_without_changes_json(tmp_path):
    result = CliRunner().invoke(app, ["eval", "changes", str(tmp_path), "--kb", str(tmp_path / "kb.hiper")])
    assert result.exit_code != 0 and "no readable changes.json" in " ".join(result.output.split())
