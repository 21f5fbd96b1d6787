"""Parsers of option values that several commands share: a duration to keep."""

from __future__ import annotations

from hiper_cli.errors import ConfigError

__all__ = ["keep_duration_s"]


def keep_duration_s(text: str) -> float | None:
    """``--keep-observations``: seconds, or None for 'all' (no summarising)."""
    if text.strip().lower() in ("all", "forever", "none"):
        return None
    try:
        return max(0.0, float(text))
    except ValueError:
        pass
    from hiper_cli.agent.times import resolve_span_s
    from hiper_cli.errors import QueryError

    try:
        return resolve_span_s(text)
    except QueryError as err:
        raise ConfigError(f"--keep-observations {text!r}: expected a duration such as '10 minutes', "
                          "'2 h', 0 or 'all'") from err
