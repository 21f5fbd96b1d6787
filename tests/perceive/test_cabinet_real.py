"""Real data as a regression: the TUM fr3/cabinet sequence (58 Kinect frames, derived truth).

What a user needs from it (../shared/worlds/README.md): a floor, one cabinet (a foreground object
of some class, or ``unknown``; not a table, not a wall), nothing moving, and no debris.
Skipped when ../shared/worlds (HIPER_WORLDS) or the YOLOX-Nano model is absent.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from typing import Any

import pytest

from hiper_cli.errors import ConfigError
from tests import WORLDS

CABINET = WORLDS / "cabinet"

pytestmark = pytest.mark.skipif(not (CABINET / "gt" / "instances.json").is_file(),
                                reason=f"needs the real cabinet log at {CABINET} (set HIPER_WORLDS)")


@pytest.fixture(scope="module")
def scored(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """``hiper perceive`` the cabinet (defaults, yolox) and ``hiper eval scene --json`` it."""
    from hiper_cli.perceive.detect.yolox import find_yolox_model

    try:
        find_yolox_model()
    except ConfigError:
        pytest.skip("YOLOX-Nano model absent (set HIPER_MODELS)")
    kb = tmp_path_factory.mktemp("cabinet") / "cabinet.hiper"
    hiper = [sys.executable, "-m", "hiper_cli"]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    subprocess.run([*hiper, "perceive", str(CABINET), "--kb", str(kb)], check=True, capture_output=True,
                   env=env)
    out = subprocess.run([*hiper, "eval", "scene", str(CABINET), "--kb", str(kb), "--json"], check=True,
                         capture_output=True, text=True, env=env).stdout
    return dict(json.loads(out))


def test_the_floor_and_nothing_else_in_the_background(scored):
    background = scored["background"]
    assert background["instances"] >= 1
    assert set(background["confusion"]) == {"floor->floor"}, background["confusion"]
    assert background["coverage"] == 1.0


def test_one_cabinet_in_the_foreground_not_a_table(scored):
    foreground = scored["foreground"]
    assert foreground["instances"] == 1, foreground["per_class"]
    lying_on = foreground["unmatched"].items()
    on_cabinet = foreground["tp"] + sum(n for k, n in lying_on if k.endswith("->cabinet"))
    assert on_cabinet == 1, foreground["unmatched"]
    assert "table" not in foreground["per_class"] and "wall" not in foreground["per_class"]


def test_nothing_moves_and_no_debris(scored):
    foreground = scored["foreground"]
    assert foreground["dynamic_instances"] == 0
    assert not any(k.endswith("->nothing") for k in foreground["unmatched"]), foreground["unmatched"]
