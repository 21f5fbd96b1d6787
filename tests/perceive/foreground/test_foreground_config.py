"""ForegroundConfig shows its concepts: dotted options by concept, the old part names and flat
names, each field in one concept, at most 40 in all."""

from dataclasses import fields

import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.foreground.config import (
    BackgroundFilterConfig,
    ForegroundConfig,
    MatchConfig,
    RefineConfig,
    SegmentConfig,
    TrackerConfig,
)
from hiper_cli.pipeline import parse_stage_options

CONCEPTS = ("segment", "associate", "fuse", "track", "classify")


def test_every_option_belongs_to_exactly_one_concept_and_there_are_few():
    names = [name for concept in CONCEPTS for name in ForegroundConfig.PARTS[concept]]
    assert len(names) == len(set(names))
    every = {f.name for f in fields(ForegroundConfig)}
    assert set(names) == every
    assert len(every) <= 40
    for old in set(ForegroundConfig.PARTS) - set(CONCEPTS):  # the older part names: subsets
        assert ForegroundConfig.PARTS[old] <= every
    assert "gate_m" in ForegroundConfig.PARTS["tracker"]
    assert "gate_m" in ForegroundConfig.PARTS["associate"]
    assert "background_margin_m" in ForegroundConfig.PARTS["background_filter"]


def test_a_foreground_config_is_each_part():
    config = ForegroundConfig()
    for part in (SegmentConfig, BackgroundFilterConfig, RefineConfig, MatchConfig, TrackerConfig):
        assert isinstance(config, part)
    assert not {f.name for f in fields(TrackerConfig)} & {f.name for f in fields(SegmentConfig)}


def test_dotted_and_flat_options_give_the_same_config():
    dotted = parse_stage_options(["foreground.tracker.gate_m=0.8", "foreground.segment.pixel_step=2",
                                  "foreground.track.stitch=false"])
    assert dotted == {"foreground": {"tracker.gate_m": 0.8, "segment.pixel_step": 2, "track.stitch": False}}
    assert ForegroundConfig.from_options(**dotted["foreground"]) == ForegroundConfig.from_options(
        gate_m=0.8, pixel_step=2, stitch=False)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"trackr.gate_m": 1.0}, "unknown part 'trackr'; expected one of segment, associate, fuse"),
        ({"segment.gate_m": 1.0}, "segment has no option 'gate_m'"),
        ({"gate_m": 1.0, "tracker.gate_m": 2.0}, "'gate_m' given twice"),
        ({"gate": 1.0}, r"unknown foreground option\(s\) \['gate'\]"),
        ({"stitch_margin_m": 1.0}, r"unknown foreground option\(s\) \['stitch_margin_m'\]"),
        ({"tracker.confirm_hits": 0}, "confirm_hits must be >= 1"),
    ],
)
def test_bad_options_name_the_part_and_the_fix(options, match):
    with pytest.raises(ConfigError, match=match):
        ForegroundConfig.from_options(**options)


def test_each_part_checks_its_own_fields():
    with pytest.raises(ConfigError, match="pixel_step must be >= 1"):
        SegmentConfig(pixel_step=0)
    with pytest.raises(ConfigError, match="iou_threshold must be in"):
        MatchConfig(iou_threshold=2.0)
    assert TrackerConfig(walker_classes="person, cart").walker_classes == ("person", "cart")
