"""One validator for every number a user types: command options and ``-o STAGE.KEY=VALUE``.

``OPTION_RANGES`` gives the accepted range of each numeric command-line option by its parameter
name (the same name means the same quantity in every command); ``check_options`` checks a
command's keyword arguments against it before the command runs (the CLI does it for every
command). ``typed_options`` checks configuration options given as text or JSON values against
the fields of a frozen config dataclass: known name (else "did you mean"), type, finiteness.
Every failure is a ``ConfigError`` naming the option, the value and the accepted range.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from hiper_cli.errors import ConfigError

__all__ = ["OPTION_RANGES", "Range", "check_number", "check_options", "typed_options"]

MAX_MAGNITUDE = 1e12  # beyond this a number in a configuration is a typo, not a setting


@dataclass(frozen=True)
class Range:
    """Accepted values: ``lo`` (exclusive when ``lo_open``) .. ``hi``, integers when ``integer``."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    integer: bool = False

    def describe(self) -> str:
        kind = "an integer" if self.integer else "a finite number"
        if self.lo is None and self.hi is None:
            return kind
        lo = "-inf" if self.lo is None else f"{self.lo:g}"
        hi = "inf" if self.hi is None else f"{self.hi:g}"
        opening = "(" if self.lo_open or self.lo is None else "["
        closing = "]" if self.hi is not None else ")"
        return f"{kind} in {opening}{lo}, {hi}{closing}"

    def admits(self, value: float) -> bool:
        if not math.isfinite(value) or (self.integer and value != int(value)):
            return False
        if self.lo is not None and (value <= self.lo if self.lo_open else value < self.lo):
            return False
        return self.hi is None or value <= self.hi


POSITIVE = Range(0.0, MAX_MAGNITUDE, lo_open=True)
FRACTION = Range(0.0, 1.0)
PIXELS = Range(1, 16384, integer=True)
COUNT = Range(0, 1 << 31, integer=True)

OPTION_RANGES: dict[str, Range] = {
    # hiper sim --sessions N --changes K (several logs of one place)
    "sessions": Range(1, 100, integer=True), "changes": Range(0, 100, integer=True),
    # camera and log flags (hiper info / perceive / convert)
    "fx_px": Range(0.0, 1e6, lo_open=True), "fy_px": Range(0.0, 1e6, lo_open=True),
    "cx_px": Range(0.0, 1e5), "cy_px": Range(0.0, 1e5),
    "width": PIXELS, "height": PIXELS, "width_px": PIXELS, "height_px": PIXELS,
    "depth_scale": Range(1e-3, 1e7),
    "max_dt_s": Range(0.0, 60.0),
    "pose_drift": Range(0.0, 1.0),  # hiper convert --degrade: metres of drift per metre travelled
    "mapping_hz": Range(0.0, 1000.0, lo_open=True), "keyframe_hz": Range(0.0, 1000.0, lo_open=True),
    "max_hz": Range(0.0, 1000.0, lo_open=True),  # hiper perceive --max-hz
    "detector_hz": Range(0.0, 1000.0),  # hiper perceive --detector-hz (0: every frame)
    # hiper analyze
    "hours": Range(0.0, 1000.0, lo_open=True), "resolution_m": Range(0.001, 10.0),
    # hiper sim
    "seconds": Range(0.0, 24 * 3600.0, lo_open=True), "rate_hz": Range(0.0, 1000.0, lo_open=True),
    "seed": Range(0, (1 << 32) - 1, integer=True), "max_range_m": Range(0.0, 1000.0, lo_open=True),
    "mapping_s": Range(0.0, 24 * 3600.0), "speed_mps": Range(0.0, 0.9, lo_open=True),
    "miss_rate": FRACTION, "jitter": Range(0.0, 1.0), "false_positives": Range(0.0, 100.0),
    "confusion": FRACTION, "png_compression": Range(0, 9, integer=True),
    # hiper eval, hiper kb bench
    "max_frames": COUNT, "queries": Range(1, 1_000_000, integer=True),
    "obs_per_frame": Range(1, 10_000, integer=True), "graph_sync_s": Range(0.0, 3600.0),
    # hiper query, describe, serve, view (stamps in seconds: log time, possibly Unix epoch)
    "start_s": Range(-1e11, 1e11), "end_s": Range(-1e11, 1e11), "recent_s": Range(0.0, 1e9),
    "limit": Range(1, 1 << 31, integer=True), "resolution": Range(0.001, 10.0),
    "instances": Range(1, 10_000_000, integer=True), "observations": Range(1, 100_000_000, integer=True),
    "port": Range(0, 65535, integer=True),
    "timeout_s": Range(0.0, 24 * 3600.0, lo_open=True),
    "short_s": Range(0.0, 1e9, lo_open=True), "glimpse_s": Range(0.0, 1e9),
    "image_hz": Range(0.0, 1000.0, lo_open=True),
    # hiper perceive zenoh:// and hiper replay (live)
    "idle_timeout": Range(0.0, 24 * 3600.0, lo_open=True), "queue": Range(1, 10_000, integer=True),
    "rate": Range(0.0, 1000.0, lo_open=True), "hz": Range(0.0, 1000.0, lo_open=True),
    "wait": Range(0.0, 3600.0),
    # hiper bench
    "runs": Range(1, 1000, integer=True), "log_s": Range(10.0, 24 * 3600.0),
    "time_limit_s": Range(1.0, 24 * 3600.0),
}


def check_number(name: str, value: float, allowed: Range) -> None:
    """Raise ``ConfigError`` unless ``value`` lies in ``allowed``; ``name`` as the user typed it."""
    if not allowed.admits(float(value)):
        raise ConfigError(f"{name} {value!r}: expected {allowed.describe()}")


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


def check_options(values: Mapping[str, Any], flags: Mapping[str, str] | None = None) -> None:
    """Check every number among a command's keyword arguments: finite, and in its range when
    ``OPTION_RANGES`` knows the option. ``flags`` maps parameter names to the flags the user
    types (default ``--name-with-dashes``)."""
    for name, value in values.items():
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        flag = (flags or {}).get(name) or _flag(name)
        allowed = OPTION_RANGES.get(name)
        if allowed is not None:
            check_number(flag, value, allowed)
        elif not (math.isfinite(float(value)) and abs(float(value)) <= MAX_MAGNITUDE):
            raise ConfigError(f"{flag} {value!r}: expected a finite number of at most "
                              f"{MAX_MAGNITUDE:g}")


def _closest(word: str, choices: list[str]) -> str:
    found = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    return f"did you mean {found[0]!r}? " if found else ""


def _coerce(where: str, value: Any, kind: Any) -> Any:
    """``value`` as a field of type ``kind`` (a JSON value or a text from the command line)."""
    origin = typing.get_origin(kind)
    args = [a for a in typing.get_args(kind) if a is not type(None)]
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in typing.get_args(kind):
            return None
        if len(args) == 1:
            return _coerce(where, value, args[0])
        return value
    if kind is bool:
        return _coerce_bool(where, value)
    if kind in (int, float):
        return _coerce_number(where, value, kind)
    if kind is str and not isinstance(value, str):
        raise ConfigError(f"{where}={value!r}: expected a text")
    return value


def _coerce_bool(where: str, value: Any) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, int) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value.lower() in ("true", "false", "1", "0", "yes", "no"):
        return value.lower() in ("true", "1", "yes")
    raise ConfigError(f"{where}={value!r}: expected true or false")


def _coerce_number(where: str, value: Any, kind: type) -> int | float:
    number = value
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            number = None
    if isinstance(number, bool) or not isinstance(number, int | float):
        raise ConfigError(f"{where}={value!r}: expected {'an integer' if kind is int else 'a number'}")
    if not math.isfinite(float(number)) or abs(float(number)) > MAX_MAGNITUDE:
        raise ConfigError(f"{where}={value!r}: expected a finite number of at most {MAX_MAGNITUDE:g}")
    if kind is int:
        if float(number) != int(number):
            raise ConfigError(f"{where}={value!r}: expected an integer")
        return int(number)
    return float(number)


def typed_options(cls: type, options: Mapping[str, Any], where: str) -> dict[str, Any]:
    """``options`` checked against the fields of the dataclass ``cls``: every name must be a
    field (else "did you mean ..."), every value of its field's type and finite. ``where`` names
    the options for messages (``-o foreground``). Nested dataclass fields take a mapping."""
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls!r} is not a dataclass")
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    out: dict[str, Any] = {}
    for key, value in options.items():
        if key not in hints or key not in names:
            raise ConfigError(f"{where}.{key}: unknown option; {_closest(key, names)}"
                              f"expected one of {', '.join(sorted(names))}")
        kind = hints[key]
        if isinstance(kind, type) and dataclasses.is_dataclass(kind) and isinstance(value, Mapping):
            out[key] = kind(**typed_options(kind, value, f"{where}.{key}"))
        else:
            out[key] = _coerce(f"{where}.{key}", value, kind)
    return out
