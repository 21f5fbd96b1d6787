"""The question corpus (``query_corpus.jsonl``, 200+ questions as users type them) against the
grammar and the house truth KB: at least 90 % of the questions handled correctly (answered
with the expected reading and a true answer, or, outside hiper's scope, refused), no crash,
and every refusal quotes what it could not read and offers a question that parses."""

from __future__ import annotations

import pytest

from tests.query_corpus import load_corpus, measure, report, shares
from tests.query_truth_kb import house_truth_kb


@pytest.fixture(scope="module")
def outcomes():
    return measure(house_truth_kb())


def test_the_corpus_is_large_and_mixed():
    corpus = load_corpus()
    assert len(corpus) >= 200
    assert len({e["q"] for e in corpus}) == len(corpus), "each question once"
    kinds = {e.get("a", "refuse") for e in corpus}
    assert kinds >= {"count", "location", "time", "duration", "yes_no", "list", "goal", "refuse"}
    assert sum(bool(e.get("typo")) for e in corpus) >= 10


def test_the_corpus_is_answered(outcomes):
    print("\n" + report(outcomes))  # the shares, with -s
    s = shares(outcomes)
    assert s["crash"] == 0.0, report(outcomes)
    assert s["useless"] == 0.0, report(outcomes)
    assert s["answered"] + s["refused_ok"] >= 0.90, report(outcomes)
    answerable = [o for o, e in zip(outcomes, load_corpus(), strict=True) if "refuse" not in e]
    assert sum(o.verdict == "answered" for o in answerable) / len(answerable) >= 0.90, report(outcomes)
    assert s["misread"] <= 0.02, report(outcomes)
