"""How documents are stored: compact JSON, orjson where it gives the same text the stdlib would
read back (``dumps``), the stdlib where a document holds what orjson would change (NaN,
infinities, tuples, integer keys, integers beyond 64 bits)."""

from __future__ import annotations

import json
from typing import Any

import orjson

from hiper_cli.model import json_default

__all__ = ["dumps", "loads"]

_ORJSON_OPTIONS = orjson.OPT_SERIALIZE_NUMPY | orjson.OPT_NON_STR_KEYS


def dumps(doc: Any) -> str:
    """Compact JSON for a document; numpy arrays become lists. orjson (~10x the stdlib encoder
    on an observation), which writes NaN and infinities as null where the stdlib writes NaN and
    Infinity and reads them back: a body holding ``null`` is parsed back and compared with the
    document (C-level, ~10 us), and the stdlib encodes it when they differ (a non-finite number,
    or what orjson would change: tuples, numpy arrays, integer keys, integers beyond 64 bits)."""
    try:
        out = orjson.dumps(doc, default=json_default, option=_ORJSON_OPTIONS)
        if b"null" not in out or _same(orjson.loads(out), doc):
            return out.decode()
    except (orjson.JSONEncodeError, TypeError):
        pass
    return json.dumps(doc, separators=(",", ":"), default=json_default)


def _same(a: Any, b: Any) -> bool:
    try:
        return bool(a == b)
    except ValueError:  # numpy arrays compare element-wise
        return False


def loads(text: str | bytes) -> Any:
    """Parse a stored document (the stdlib parser for bodies holding NaN or Infinity)."""
    try:
        return orjson.loads(text)
    except orjson.JSONDecodeError:
        return json.loads(text)
