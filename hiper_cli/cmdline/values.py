"""Parsers of option values that several commands share: a duration to keep, a HOST:PORT."""

from __future__ import annotations

from hiper_cli.errors import ConfigError

__all__ = ["host_port", "keep_duration_s"]


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


def host_port(text: str, flag: str = "--http") -> tuple[str, int]:
    """``HOST:PORT`` (HOST defaults to 127.0.0.1)."""
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ConfigError(f"{flag} {text!r}: expected HOST:PORT, e.g. 127.0.0.1:8765")
    return host or "127.0.0.1", int(port)
