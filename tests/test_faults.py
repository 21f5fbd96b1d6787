"""The fault suite (tests/faults): every case ends in time, without a traceback, with the exit
code and one-line message it should, and with the knowledge base whole; kill -9 at ten moments
of perceive, export, import, analyze and reanchor never loses committed data.

The selected cases run two at a time once per session (``outcomes``); each test asserts its
own. ``python -m tests.faults --docs docs/reliability.md`` writes the same outcomes as a table.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from tests.faults.corpus import KILL_KINDS, KILLS_PER_KIND, Case, all_cases
from tests.faults.runner import REPO, Outcome, build_cache, kill_case, run_case

CASES = all_cases()
WORKERS = max(2, min(4, os.cpu_count() or 2))  # the cases mostly wait on hiper processes


@pytest.fixture(scope="session")
def fault_cache(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    cache = tmp_path_factory.mktemp("fault-cache")
    return cache, build_cache(REPO, cache)


@pytest.fixture(scope="session")
def outcomes(request: pytest.FixtureRequest, fault_cache: tuple[Path, dict[str, Any]]) -> dict[str, Outcome]:
    """The outcome of every selected case, run ``WORKERS`` at a time."""
    selected = [item.callspec.params["case"] for item in request.session.items
                if item.originalname == "test_fault_case" and hasattr(item, "callspec")]
    cache, totals = fault_cache
    with ThreadPoolExecutor(WORKERS) as pool:
        done = pool.map(lambda case: run_case(case, REPO, cache, totals), selected)
        return {o.name: o for o in done}


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_fault_case(case: Case, outcomes: dict[str, Outcome]) -> None:
    outcome = outcomes[case.name]
    assert outcome.verdict == "pass", f"{outcome.verdict} (exit {outcome.exit_code}): {outcome.message} " \
                                      f"{outcome.problems}"


@pytest.mark.parametrize("kind", KILL_KINDS)
def test_kill_minus_nine_at_ten_moments(kind: str, fault_cache: tuple[Path, dict[str, Any]]) -> None:
    cache, totals = fault_cache
    with ThreadPoolExecutor(WORKERS) as pool:
        runs = list(pool.map(lambda i: kill_case(kind, i, REPO, cache, totals), range(KILLS_PER_KIND)))
    bad = [f"{o.name}: {o.verdict}: {o.message}" for o in runs if o.verdict != "pass"]
    assert not bad, "\n".join(bad)
    killed = sum(o.exit_code == -9 for o in runs)
    assert killed >= KILLS_PER_KIND // 2, f"only {killed} of {KILLS_PER_KIND} runs were killed mid-way"


def test_reliability_table_lists_every_case() -> None:
    table = (REPO / "docs" / "reliability.md").read_text()
    missing = [c.name for c in CASES if f"`{c.name}`" not in table]
    assert not missing, f"docs/reliability.md is stale; run python -m tests.faults --docs " \
                        f"docs/reliability.md (missing {missing})"
