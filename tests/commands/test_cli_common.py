"""The shared CLI options: the log flags are exactly ``LogOptions``, and reach it unchanged."""

import dataclasses
import typing
from pathlib import Path

import pytest

from hiper_cli.cmdline import LOG_FLAGS, with_log_flags
from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs import LogOptions
from hiper_cli.pipeline import PerceiveOptions


def test_log_flags_match_log_options_fields_types_and_defaults():
    fields = {f.name: f for f in dataclasses.fields(LogOptions)}
    hints = typing.get_type_hints(LogOptions)
    assert list(LOG_FLAGS) == list(fields)
    for name, (kind, default, flags, _) in LOG_FLAGS.items():
        assert kind == hints[name], name
        assert default == fields[name].default, name
        assert all(f.startswith("--") for f in flags)


def test_with_log_flags_hands_the_command_one_log_options():
    seen = {}

    def command(log: Path, *, log_options: LogOptions) -> None:
        seen["options"] = log_options

    wrapped = with_log_flags(command)
    values = {name: default for name, (_, default, _, _) in LOG_FLAGS.items()}
    wrapped(Path("x"), **{**values, "preset": "fr1", "max_dt_s": 0.01})
    assert seen["options"] == LogOptions(preset="fr1", max_dt_s=0.01)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"preset": "fr1", "fx_px": 500.0}, "choose one of --camera, --preset"),
        ({"fx_px": 500.0, "fy_px": 500.0}, "missing --cx --cy --width --height"),
        ({"preset": "fr9"}, "--preset fr9: unknown preset; expected one of fr1"),
    ],
)
def test_log_options_reject_contradicting_camera_choices(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        LogOptions(**kwargs)


def test_perceive_options_from_text_merge_flags_over_dash_o():
    options = PerceiveOptions.from_text(
        stages="background, foreground", options=["foreground.detector=log", "background.keyframe_hz=2"],
        overrides={"foreground": {"detector": "truth", "classes": None}, "background": {"keyframe_hz": None}},
        env_name="house", resume=True)
    assert options.stages == ("background", "foreground")
    assert options.stage_options == {"foreground": {"detector": "truth"}, "background": {"keyframe_hz": 2}}
    assert (options.env_name, options.resume) == ("house", True)
    assert PerceiveOptions.from_text().stages is None
    with pytest.raises(ConfigError, match=r"expected STAGE\.KEY=VALUE"):
        PerceiveOptions.from_text(options=["detector=truth"])
