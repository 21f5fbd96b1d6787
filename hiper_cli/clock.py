"""The log's own clock: how a stamp is shown to people and machines.

A log's stamps are either wall-clock time (seconds since 1970, as TUM's and ROS's) or a clock
that starts near 0 (a ``hiper sim`` log, a bag recorded with simulated time). Reading the second
kind as dates prints January 1970, which is false; so a stamp below ``WALL_CLOCK_MIN_S`` (1973)
is shown as seconds of log time, and a wall-clock stamp as ISO 8601 in UTC with its zone.
"""

from __future__ import annotations

from datetime import UTC, datetime

__all__ = ["WALL_CLOCK_MIN_S", "is_wall_clock", "iso_utc", "span_text", "stamp_text"]

# Stamps above this are seconds since 1970 (1973-03-03); below it, seconds since the log began.
WALL_CLOCK_MIN_S = 1e8


def is_wall_clock(stamp_s: float) -> bool:
    """Whether ``stamp_s`` reads as wall-clock time (seconds since 1970)."""
    return stamp_s > WALL_CLOCK_MIN_S


def iso_utc(stamp_s: float) -> str | None:
    """ISO 8601 in UTC with its zone ("2011-05-10T15:18:22.123Z") for a wall-clock stamp;
    None for a stamp of log time, which has no date."""
    if not is_wall_clock(stamp_s):
        return None
    return datetime.fromtimestamp(stamp_s, UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")


def stamp_text(stamp_s: float) -> str:
    """The stamp as a person reads it: ISO 8601 UTC for wall-clock time, else "12.300 s" of
    log time."""
    return iso_utc(stamp_s) or f"{stamp_s:.3f} s"


def span_text(t0_s: float, t1_s: float, spec: str = ".2f") -> str:
    """A time span: "t 0.00-14.75 s" of log time, or "2011-05-10T15:18:22.123Z + 40.25 s" for
    wall-clock stamps (the start as a date, then the duration)."""
    start = iso_utc(t0_s)
    if start is None:
        return f"t {t0_s:{spec}}-{t1_s:{spec}} s"
    return f"{start} + {t1_s - t0_s:{spec}} s"
