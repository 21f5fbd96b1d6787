"""Golden Table III numbers on the committed fixture log: a foreground regression fails loudly.

fixtures/house_small (house, seed 4, 4 Hz, 256x192, one person), truth detector, ground-truth
background boxes (so that a change of the background stage does not move these numbers).
Main before branch fg3 gave TP 5 (a potted plant named from 2 observations, now below
``min_class_observations``), FP 0, localisation 0.0328 m; fg3 0.0282 m (median 0.0237 m).
Trimming that keeps what a jittered box cut at the blob's depth: 0.0262 m (median 0.0187 m).
Background margin 0.03 -> 0.02 m: 0.0242 m (median 0.0147 m), and one chair of this 256x192
log stayed ``unknown``; joining blobs by depth range instead of median depth brings it back
(its back legs join it): 0.0249 m (median 0.0147 m). The background test at each sample's
pixel-block mean with a margin of 0.0015 m per m² (was 0.005), no support below a blob cut by
the image's lower edge, and 0.3 m of range slack: 0.0177 m (median 0.0110 m); the fourth chair
is classified, and the tracker switches identity 3 times. Sixth round: a class needs 4
observations (was 3; this 4 Hz log's fourth chair has 3 and stays ``unknown``), support unless
a blob's lowest points are at the lower edge, settled tracks: 0.0161 m (median 0.0103 m).
"""

from pathlib import Path

import pytest

from hiper_cli.evaluate.foreground import evaluate_foreground

FIXTURE = Path(__file__).resolve().parents[1] / "fixtures" / "house_small"


def test_golden_table_iii_on_the_fixture():
    report = evaluate_foreground(FIXTURE, detector="truth", ablation=False, background="truth")
    ours = report["ours"]
    assert ours["classification"] == {"chair": {"tp": 3, "fp": 0}, "person": {"tp": 1, "fp": 0}}
    assert (ours["unknown_instances"], ours["sum_i"], ours["sum_o"]) == (3, 7, 103)
    assert ours["identity_switches"] == 3 and ours["truth_instances_seen"] == 7
    assert ours["localisation_classified_m"][0] == pytest.approx(0.0161, abs=0.003)
    assert ours["localisation_visible_median_m"] == pytest.approx(0.0103, abs=0.003)
    assert ours["localisation_box_centre_m"][0] == pytest.approx(0.298, abs=0.05)
