"""The time window of an analysis: [t0, t1] in seconds, optionally only a daily time of day.

Stamps are the log's seconds (Unix time for a real robot, log time for a simulation); a time of
day is taken from a stamp as UTC (``stamp mod 86400``). ``--last 1h`` counts back from the
newest stamp in the knowledge base, not from the wall clock, so an old log analyses the same
way tomorrow.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import UTC, datetime

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError

__all__ = ["TimeWindow", "parse_duration_s", "parse_stamp_s", "resolve_window"]

DAY_S = 86400.0
_UNITS = {"s": 1.0, "m": 60.0, "min": 60.0, "h": 3600.0, "d": DAY_S}


@dataclass(frozen=True)
class TimeWindow:
    """Stamps in [``t_start_s``, ``t_end_s``] (None: open); with ``daily_s`` = (start, end)
    seconds of the day, only those times of each day (an end before the start wraps midnight)."""

    t_start_s: float | None = None
    t_end_s: float | None = None
    daily_s: tuple[float, float] | None = None

    def mask(self, stamps_s: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Which stamps lie in the window."""
        keep = np.ones(len(stamps_s), dtype=bool)
        if self.t_start_s is not None:
            keep &= stamps_s >= self.t_start_s
        if self.t_end_s is not None:
            keep &= stamps_s <= self.t_end_s
        if self.daily_s is not None:
            a, b = self.daily_s
            tod = np.mod(stamps_s, DAY_S)
            keep &= (tod >= a) & (tod < b) if a <= b else (tod >= a) | (tod < b)
        return keep

    def to_dict(self) -> dict[str, object]:
        daily = None
        if self.daily_s is not None:
            daily = "-".join(f"{int(v // 3600):02d}:{int(v % 3600 // 60):02d}" for v in self.daily_s)
        return {"t_start_s": self.t_start_s, "t_end_s": self.t_end_s, "daily": daily}

    def describe(self) -> str:
        """A short text for titles: 't 10.0 to 70.0 s, daily 09:00-10:00'."""
        if self.t_start_s is None and self.t_end_s is None:
            text = "all times"
        else:
            lo = "start" if self.t_start_s is None else f"{self.t_start_s:.1f}"
            hi = "end" if self.t_end_s is None else f"{self.t_end_s:.1f}"
            text = f"t {lo} to {hi} s"
        daily = self.to_dict()["daily"]
        return f"{text}, daily {daily}" if daily else text


def parse_duration_s(text: str) -> float:
    """'90', '90s', '15min', '1h', '2d' -> seconds."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+)\s*(s|m|min|h|d)?\s*", text)
    if not m:
        raise ConfigError(f"duration {text!r}: expected a number with s, min, h or d, e.g. '1h' or '90s'")
    return float(m.group(1)) * _UNITS[m.group(2) or "s"]


def parse_stamp_s(text: str) -> float:
    """A stamp in seconds, or an ISO date-time ('2024-05-01T09:00', UTC unless it says)."""
    try:
        return float(text)
    except ValueError:
        pass
    try:
        when = datetime.fromisoformat(text)
    except ValueError as err:
        raise ConfigError(
            f"time {text!r}: expected seconds (e.g. 120.5) or an ISO date-time (e.g. 2024-05-01T09:00)"
        ) from err
    if when.tzinfo is None:
        when = when.replace(tzinfo=UTC)
    return when.timestamp()


def _time_of_day_s(text: str) -> float:
    m = re.fullmatch(r"(\d{1,2}):(\d{2})(?::(\d{2}))?", text.strip())
    if not m or int(m.group(1)) > 24 or int(m.group(2)) > 59:
        raise ConfigError(f"time of day {text!r}: expected HH:MM, e.g. 09:00")
    return int(m.group(1)) * 3600.0 + int(m.group(2)) * 60.0 + int(m.group(3) or 0)


def resolve_window(
    *,
    t_from: str | None = None,
    t_to: str | None = None,
    last: str | None = None,
    daily: str | None = None,
    newest_stamp_s: float | None = None,
) -> TimeWindow:
    """The window the options ``--from``/``--to``, ``--last`` and ``--daily`` describe."""
    if last is not None and (t_from is not None or t_to is not None):
        raise ConfigError("--last counts back from the newest data: give it alone, without --from/--to")
    t0 = parse_stamp_s(t_from) if t_from is not None else None
    t1 = parse_stamp_s(t_to) if t_to is not None else None
    if last is not None:
        span = parse_duration_s(last)
        if newest_stamp_s is not None:
            t0, t1 = newest_stamp_s - span, newest_stamp_s
    if t0 is not None and t1 is not None and t1 < t0:
        raise ConfigError(f"--to {t1} is before --from {t0}: swap them")
    daily_s = None
    if daily is not None:
        parts = daily.split("-")
        if len(parts) != 2:
            raise ConfigError(f"--daily {daily!r}: expected HH:MM-HH:MM, e.g. 09:00-10:00")
        daily_s = (_time_of_day_s(parts[0]), _time_of_day_s(parts[1]))
    return TimeWindow(t0, t1, daily_s)
