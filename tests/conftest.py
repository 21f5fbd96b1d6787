"""Fixtures every test folder shares.

``house_kb``: the knowledge base built from the house sim log's truth (``query_truth_kb.py``),
made once per run; the query and MCP tests ask it. Paths shared by every folder
(``REPO_ROOT``, the realistic worlds' ``WORLDS``) are in ``tests/__init__.py``.
"""

from __future__ import annotations

import pytest

from tests.query_truth_kb import TruthKb, house_truth_kb


@pytest.fixture(scope="session")
def house_kb() -> TruthKb:
    return house_truth_kb()


@pytest.fixture(scope="session")
def house_kb_path(house_kb: TruthKb) -> str:
    return str(house_kb.path)
