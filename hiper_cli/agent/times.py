"""Times as an agent writes them, resolved by the server so an agent never does date
arithmetic: a stamp (s), "now", "10 minutes ago", "last 10 minutes", "10:30", ISO 8601, or
any time phrase of the query grammar ("today", "this morning", "since 9am": its start)."""

from __future__ import annotations

import re
from typing import Any

from hiper_cli.errors import QueryError

__all__ = ["TIME_HELP", "resolve_span_s", "resolve_time"]

TIME_HELP = (
    "a stamp in seconds, 'now', a relative time ('10 minutes ago', 'last 10 minutes', '2 h'), "
    "a time of day 'HH:MM' (UTC), an ISO 8601 date-time or a phrase such as 'today' or 'this "
    "morning' (its start); the server resolves it against the knowledge base's now"
)
_UNITS = {
    "s": 1.0, "sec": 1.0, "secs": 1.0, "second": 1.0, "seconds": 1.0,
    "m": 60.0, "min": 60.0, "mins": 60.0, "minute": 60.0, "minutes": 60.0,
    "h": 3600.0, "hr": 3600.0, "hrs": 3600.0, "hour": 3600.0, "hours": 3600.0,
    "d": 86400.0, "day": 86400.0, "days": 86400.0,
}
_SPAN = re.compile(r"(?:(?:in\s+)?(?:the\s+)?(?:last|past)\s+)?([0-9]*\.?[0-9]+)?\s*([a-z]+)(?:\s+ago)?")


def resolve_span_s(value: Any) -> float:
    """A duration: seconds, or words such as '10 minutes', 'last 2 h', '90 s'."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    text = str(value).strip().lower()
    m = _SPAN.fullmatch(text)
    if m is None or m.group(2) not in _UNITS:
        raise QueryError(f"duration {value!r}: expected seconds or e.g. '10 minutes', '2 h', '90 s'")
    return float(m.group(1) or 1.0) * _UNITS[m.group(2)]


def resolve_time(value: Any, now_s: float) -> float:
    """A stamp (s) for a time an agent gave (see ``TIME_HELP``)."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    text = str(value).strip().lower()
    if text in ("now", "right now"):
        return now_s
    try:
        return float(text)
    except ValueError:
        pass
    if (_SPAN.fullmatch(text) and any(text.startswith(w) for w in ("last", "past", "in the"))) or (
        text.endswith(" ago")
    ):
        return now_s - resolve_span_s(text)
    from hiper_cli.query.timewords import clock_stamp, time_window

    stamp = clock_stamp(text, now_s)
    if stamp is not None:
        return stamp
    try:
        window = time_window(text, now_s)
    except QueryError:
        window = None
    bound = None if window is None else window.since_s if window.since_s is not None else window.until_s
    if bound is None:
        raise QueryError(f"time {value!r}: expected {TIME_HELP}")
    return bound
