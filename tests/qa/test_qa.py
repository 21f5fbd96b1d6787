"""``hiper eval qa``: questions from truth, asked through the query layer, scored. On a KB
built from the truth itself every answer must be right (a wrong one is the benchmark's
fault); the worlds' gt/ format yields questions too; the CLI prints --json and one-line errors."""

from __future__ import annotations

import json
import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.qa import KINDS, evaluate_qa, generate_questions, load_scene_truth
from hiper_cli.qa.run import vocabulary_of
from tests import WORLDS
from tests.query_truth_kb import MIN_PIXELS, house_truth_kb

runner = CliRunner()
FRACTION = MIN_PIXELS / (160 * 120)  # the truth KB's own visibility threshold


def test_a_truth_kb_answers_every_question_right(tmp_path):
    k = house_truth_kb()
    report = evaluate_qa(k.path.parent / "log", kb=str(k.path), out_dir=tmp_path, min_pixel_fraction=FRACTION)
    data = report.to_dict()
    assert data["binary_accuracy"] == 1.0 and data["count_accuracy"] == 1.0
    assert data["position_error_median_m"] < 1e-3 and data["time_error_median_s"] < 1e-6
    assert data["duration_error_median_s"] < 1e-6
    kinds = Counter((s.question.kind, s.question.horizon) for s in report.scored)
    for kind in KINDS:
        assert kinds[(kind, "long")] > 0
    for kind in ("yes_no", "count", "position", "time"):
        assert kinds[(kind, "short")] > 0
    yes_no = data["by_kind"]["yes_no"]["all"]
    assert 0 < yes_no["true_yes"] < yes_no["n"]  # both answers occur
    # what the answers stand on, measured by hiper_cli.evaluate: the truth's own objects
    perception = data["perception"]
    assert perception["scored"] == "knowledge base"
    assert perception["foreground"]["classified_precision"] == 1.0
    assert perception["recall"]["truth_found"] >= perception["recall"]["truth_observed"] - 1  # not the door


def test_questions_are_deterministic_and_written_with_their_answers(tmp_path):
    k = house_truth_kb()
    log = k.path.parent / "log"
    scene = load_scene_truth(log)
    vocabulary = vocabulary_of(log, "truth")
    a = [q.to_dict() for q in generate_questions(scene, seed=3, vocabulary=vocabulary)]
    assert a == [q.to_dict() for q in generate_questions(scene, seed=3, vocabulary=vocabulary)]
    assert a != [q.to_dict() for q in generate_questions(scene, seed=4)]  # "after T" times differ
    assert {q["class_name"] for q in a if not q["named"]} >= {"shelf"}  # the truth detector's classes
    report = evaluate_qa(log, kb=str(k.path), out_dir=tmp_path, seed=3, min_pixel_fraction=0.001)
    lines = [json.loads(x) for x in Path(report.files["questions"]).read_text().splitlines()]
    assert lines == json.loads(json.dumps(a))
    assert {"text", "answer", "kind", "horizon", "now_s", "pose"} <= set(lines[0])


@pytest.mark.skipif(not (WORLDS / "bookstore" / "gt" / "instances.json").exists(),
                    reason="the realistic worlds are not in ../shared/worlds")
def test_a_world_gt_yields_questions():
    scene = load_scene_truth(WORLDS / "bookstore")
    questions = generate_questions(scene)
    assert {"chair", "person"} <= set(scene.classes())
    assert {q.kind for q in questions} == set(KINDS)
    person = [q for q in questions if q.text == "how many people"]
    assert person and person[0].answer == 2


def test_cli_json_and_errors(tmp_path):
    k = house_truth_kb()
    result = runner.invoke(app, ["eval", "qa", str(k.path.parent / "log"), "--kb", str(k.path),
                                 "-o", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output, parse_constant=lambda c: pytest.fail(f"not JSON: {c}"))
    assert data["format"] == "hiper-eval-qa" and data["questions"] > 50
    yes_no, count = data["by_kind"]["yes_no"]["all"], data["by_kind"]["count"]["all"]
    assert "median_error" not in yes_no and "median_error" not in count
    assert {"accuracy_glimpses_optional", "glimpsed"} <= set(count)
    result = runner.invoke(app, ["eval", "qa", str(tmp_path / "nothing")])
    assert result.exit_code != 0 and "not found" in result.output and "Traceback" not in result.output
    result = runner.invoke(app, ["eval", "qa", str(tmp_path), "--short-s", "0"])
    assert result.exit_code != 0 and "--short-s" in result.output


def test_several_logs_are_one_benchmark_with_figures_over_all_questions(tmp_path):
    k = house_truth_kb()
    log = str(k.path.parent / "log")
    one = evaluate_qa(log, kb=str(k.path), out_dir=tmp_path / "one")
    result = runner.invoke(app, ["eval", "qa", log, log, "--kb", str(k.path), "--kb", str(k.path),
                                 "-o", str(tmp_path / "set"), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["format"] == "hiper-eval-qa-set" and len(data["logs"]) == 2
    assert data["questions"] == 2 * one.figures["questions"]
    for key in ("binary_accuracy", "count_accuracy", "position_error_median_m", "time_error_median_s"):
        assert data[key] == one.figures[key] and data["logs"][1][key] == one.figures[key]
    assert sorted(p.name for p in (tmp_path / "set").iterdir()) == ["log", "log-2"]
    assert (tmp_path / "set" / "log-2" / "answers.jsonl").exists()
    result = runner.invoke(app, ["eval", "qa", log, log, "--kb", str(k.path)])
    assert result.exit_code != 0 and "1 --kb for 2 logs" in result.output
    result = runner.invoke(app, ["eval", "qa", log, str(tmp_path / "nothing"), "-o", str(tmp_path / "x")])
    assert result.exit_code != 0 and "nothing" in result.output and "not found" in result.output
    assert not (tmp_path / "x").exists()  # named before the first log is perceived


def test_without_a_kb_the_log_is_perceived_with_the_truth_detector(tmp_path):
    log = house_truth_kb().path.parent / "log"
    report = evaluate_qa(log, out_dir=tmp_path)
    assert report.detector == "truth" and (tmp_path / "kb.hiper").is_dir()
    assert report.figures["questions"] > 50 and "perceive" in report.seconds


def test_after_and_before_answers_hold_for_the_time_the_question_names():
    """The words say whole seconds ("after 00:00:36"); the true answer must be taken at that
    second. A bottle seen at 36.03 s was there after 00:00:36, whatever fraction was drawn."""
    scene = load_scene_truth(house_truth_kb().path.parent / "log")
    asked = 0
    for seed in range(8):
        for q in generate_questions(scene, seed=seed):
            found = re.fullmatch(r"was there an? (.+) (after|before) (\d\d):(\d\d):(\d\d)", q.text)
            if found is None:
                continue
            cls, word = found.group(1), found.group(2)
            at_s = int(found.group(3)) * 3600 + int(found.group(4)) * 60 + int(found.group(5))
            seen = [scene.seen[i.id] for i in scene.instances(cls)]
            after = [np.any(s >= at_s - 1e-6) for s in seen]
            before = [np.any(s <= at_s + 1e-6) for s in seen]
            truth = any(after if word == "after" else before)
            assert q.answer == truth, q.text
            asked += 1
    assert asked > 50


def test_a_count_missing_only_glimpsed_instances_is_right_with_glimpses_optional():
    """A cup in view for two frames is in the truth's count; a perceiver that confirms what it
    sees cannot count it. The strict score says wrong, the one with glimpses optional right; a
    count missing a cup in view for long is wrong both ways."""
    from dataclasses import replace

    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.qa.score import answer_question, summarise

    k = house_truth_kb()
    log = k.path.parent / "log"
    scene = load_scene_truth(log, min_pixel_fraction=FRACTION)
    counts = [q for q in generate_questions(scene, glimpse_s=0.0) if q.kind == "count"]
    assert counts and all(q.glimpsed == 0 for q in counts)
    every = [q for q in generate_questions(scene, glimpse_s=1e9) if q.kind == "count"]
    assert all(q.glimpsed == q.answer for q in every)  # nothing is in view that long
    q = next(q for q in counts if q.answer > 0)
    with open_kb_for_reading(str(k.path)) as kb:
        right = answer_question(kb, q)
        one_more_glimpsed = answer_question(kb, replace(q, answer=q.answer + 1, glimpsed=1))
        one_more_seen = answer_question(kb, replace(q, answer=q.answer + 1))
    assert right.correct and right.right_but_glimpses
    assert not one_more_glimpsed.correct and one_more_glimpsed.right_but_glimpses
    assert not one_more_seen.correct and not one_more_seen.right_but_glimpses
    figures = summarise([right, one_more_glimpsed, one_more_seen])
    assert figures["count_accuracy"] == pytest.approx(1 / 3)
    assert figures["count_accuracy_glimpses_optional"] == pytest.approx(2 / 3)
    assert one_more_glimpsed.to_dict()["glimpsed"] == 1
