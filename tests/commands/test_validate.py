"""The shared validator: numeric command options and typed configuration options."""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field

import pytest
import typer.main

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.validate import OPTION_RANGES, Range, check_options, typed_options


def _numeric_options() -> list[tuple[str, str]]:
    """(command, parameter) of every int or float option of every command."""
    found: list[tuple[str, str]] = []

    def walk(command: object, path: str) -> None:
        for name, sub in getattr(command, "commands", {}).items():
            walk(sub, f"{path} {name}".strip())
        callback = getattr(command, "callback", None)
        if callback is None or hasattr(command, "commands"):
            return
        for name, p in inspect.signature(callback, eval_str=True).parameters.items():
            hint = str(p.annotation)
            numeric = hint.split(",")[0]  # Annotated[int, typer.Option(help=...)]: the type alone
            numeric_type = any(t in numeric for t in ("int", "float"))
            if numeric_type and not any(t in numeric for t in ("list", "bool")):
                found.append((path, name))

    walk(typer.main.get_command(app), "")
    return found


def test_every_numeric_option_has_a_range():
    options = _numeric_options()
    assert ("sim", "seconds") in options and ("perceive", "fx_px") in options
    missing = sorted({name for _, name in options if name not in OPTION_RANGES})
    assert not missing, f"numeric options without a range in hiper_cli.validate.OPTION_RANGES: {missing}"


@pytest.mark.parametrize(("name", "value", "match"), [
    ("seconds", math.inf, r"--seconds inf: expected a finite number in \(0, 86400\]"),
    ("rate_hz", math.nan, "--rate-hz nan"),
    ("seed", -1, r"--seed -1: expected an integer in \[0, 4.29497e\+09\]"),
    ("fx_px", 1e308, "--fx-px 1e"),
    ("cx_px", -1e9, "--cx-px -1"),
    ("depth_scale", 1e-300, "--depth-scale 1e-300"),
    ("false_positives", 1e9, "--false-positives"),
    ("obs_per_frame", 0, "--obs-per-frame 0"),
    ("max_frames", -1, "--max-frames -1"),
    ("somewhere_new", math.inf, "--somewhere-new inf: expected a finite number"),
])
def test_out_of_range_options_are_refused(name, value, match):
    with pytest.raises(ConfigError, match=match) as err:
        check_options({name: value})
    assert err.value.exit_code == 2


def test_defaults_and_non_numbers_pass():
    check_options({"seconds": 60.0, "seed": 0, "width": 640, "json_out": True, "out": "x", "mapping_s": None})


def test_range_bounds():
    assert Range(0.0, 1.0, lo_open=True).admits(1.0) and not Range(0.0, 1.0, lo_open=True).admits(0.0)
    assert not Range(0, 9, integer=True).admits(2.5)


@dataclass(frozen=True)
class _Inner:
    gate_m: float = 1.0


@dataclass(frozen=True)
class _Config:
    pixel_step: int = 4
    keyframe_hz: float = 1.0
    detector: str = "yolox"
    smooth: bool = True
    classes: tuple[str, ...] = ()
    limit: float | None = None
    inner: _Inner = field(default_factory=_Inner)


def test_typed_options_coerce_and_check():
    typed = typed_options(_Config, {"pixel_step": "2", "keyframe_hz": 3, "smooth": "false",
                                    "limit": "0.5", "inner": {"gate_m": 2}}, "-o foreground")
    assert typed == {"pixel_step": 2, "keyframe_hz": 3.0, "smooth": False, "limit": 0.5,
                     "inner": _Inner(gate_m=2.0)}


@pytest.mark.parametrize(("options", "match"), [
    ({"pixel_step": "abc"}, r"-o foreground.pixel_step='abc': expected an integer"),
    ({"pixel_step": 2.5}, "expected an integer"),
    ({"keyframe_hz": "NaN"}, "expected a finite number"),
    ({"keyframe_hz": 1e300}, "expected a finite number"),
    ({"pixel_stp": 2}, "-o foreground.pixel_stp: unknown option; did you mean 'pixel_step'"),
    ({"detector": 3}, "expected a text"),
    ({"smooth": "perhaps"}, "expected true or false"),
    ({"inner": {"gate": 1}}, r"-o foreground.inner.gate: unknown option; did you mean 'gate_m'"),
])
def test_typed_options_refuse(options, match):
    with pytest.raises(ConfigError, match=match):
        typed_options(_Config, options, "-o foreground")
