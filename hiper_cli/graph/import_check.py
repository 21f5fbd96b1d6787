"""Validate imported documents before anything is written: a bad one names its place and field.

An import must not save what later breaks the knowledge base (a uuid that is no IRI, a layer
the graph has no named graph for, a box of text, a stamp of ``inf``). ``check_documents`` gets
``(where, document)`` pairs in their ``to_dict`` form, ``where`` saying where in the source the
document came from (``instances[3]``, ``node <urn:uuid:...>``), and raises ``DataError`` at the
first problem; ``check_json_shape`` checks the outline of a JSON export first.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hiper_cli.errors import DataError

__all__ = ["check_documents", "check_json_shape"]

UUID_RE = re.compile(r"^[0-9a-fA-F]{8}-[0-9a-fA-F]{4}-[0-9a-fA-F]{4}-[0-9a-fA-F]{4}-[0-9a-fA-F]{12}$")
PERCEIVED_LAYERS = ("background", "foreground")
STATES = ("static", "dynamic")
SECTIONS = ("environments", "sessions", "instances", "analyses", "changes", "observations")
MAX_ABS = 1e12  # larger coordinates or stamps are taken for damage


class _Bad(Exception):
    def __init__(self, field: str, problem: str) -> None:
        super().__init__(field)
        self.field = field
        self.problem = problem


def check_json_shape(data: Any, source: Path) -> None:
    """The outline of a JSON export: an object whose sections are lists of objects."""
    if not isinstance(data, dict):
        raise DataError(f"{source}: the top level is a JSON {type(data).__name__}, expected an object "
                        "written by 'hiper export --format json'")
    for section in SECTIONS:
        items = data.get(section, [])
        if not isinstance(items, list):
            raise DataError(f"{source}: '{section}' is a {type(items).__name__}, expected a list; "
                            "nothing was imported")
        for k, item in enumerate(items):
            if not isinstance(item, dict):
                raise DataError(f"{source}: {section}[{k}] is a {type(item).__name__}, expected an "
                                "object; nothing was imported")


def check_documents(docs: Sequence[tuple[str, dict[str, Any]]], source: Path) -> None:
    """Raise ``DataError`` naming the first bad document (where, uuid) and field."""
    for where, doc in docs:
        try:
            _check(doc)
        except _Bad as bad:
            uuid = doc.get("uuid")
            name = f"{where} (uuid {uuid!r})" if isinstance(uuid, str) else where
            raise DataError(f"{source}: {name}: '{bad.field}' {bad.problem}; nothing was imported, fix "
                            "or remove that document") from None


def _check(doc: dict[str, Any]) -> None:
    _uuid(doc, "uuid")
    kind = doc.get("type")
    if kind == "environment":
        _text(doc, "name")
    elif kind in ("instance", "observation"):
        if doc.get("layer") not in PERCEIVED_LAYERS:
            raise _Bad("layer", f"is {doc.get('layer')!r}, expected one of {', '.join(PERCEIVED_LAYERS)}")
        _text(doc, "class")
        _box(doc.get("box"))
        _number(doc, "confidence", 0.0, 1.0)
        if kind == "instance":
            _number(doc, "first_seen_s")
            _number(doc, "last_seen_s")
            if doc.get("state", "static") not in STATES:
                raise _Bad("state", f"is {doc.get('state')!r}, expected one of {', '.join(STATES)}")
            links = doc.get("observation_uuids", [])
            if not isinstance(links, list):
                raise _Bad("observation_uuids", "is not a list of uuids")
            for k, link in enumerate(links):
                if not isinstance(link, str) or not UUID_RE.match(link):
                    raise _Bad(f"observation_uuids[{k}]", f"is {link!r}, not a uuid")
        else:
            _number(doc, "stamp_s")
            if not isinstance(doc.get("pose_id", -1), int) or isinstance(doc.get("pose_id"), bool):
                raise _Bad("pose_id", f"is {doc.get('pose_id')!r}, expected an integer")
            if doc.get("instance_uuid") is not None:
                _uuid(doc, "instance_uuid")
        if not isinstance(doc.get("data", {}), dict):
            raise _Bad("data", "is not an object")
    elif kind == "analysis":
        _text(doc, "kind")
        if doc.get("class") is not None:
            _text(doc, "class")
        for key in ("t_start_s", "t_end_s", "created_s"):
            _number(doc, key)
        if not isinstance(doc.get("values"), dict):
            raise _Bad("values", "is not an object")
    elif kind == "change":
        _change(doc)
    else:
        raise _Bad("type", f"is {kind!r}, expected environment, instance, observation, analysis or change")


def _change(doc: dict[str, Any]) -> None:
    """A change event (``history.py``): its kind, instance, session, stamp and positions."""
    if doc.get("kind") not in ("added", "removed", "moved"):
        raise _Bad("kind", f"is {doc.get('kind')!r}, expected added, removed or moved")
    _text(doc, "class")
    _uuid(doc, "instance_uuid")
    _number(doc, "stamp_s")
    if not isinstance(doc.get("session"), int) or isinstance(doc.get("session"), bool):
        raise _Bad("session", f"is {doc.get('session')!r}, expected a session id")
    for key in ("from_m", "to_m"):
        value = doc.get(key)
        if value is not None and not (isinstance(value, list) and len(value) == 3
                                      and all(isinstance(v, int | float) for v in value)):
            raise _Bad(key, f"is {value!r}, expected null or [x, y, z] in metres")


def _uuid(doc: dict[str, Any], key: str) -> None:
    value = doc.get(key)
    if value is None:
        raise _Bad(key, "is missing")
    if not isinstance(value, str) or not UUID_RE.match(value):
        raise _Bad(key, f"is {value!r}, not a uuid (8-4-4-4-12 hex digits)")


def _text(doc: dict[str, Any], key: str) -> None:
    value = doc.get(key)
    if not isinstance(value, str) or not value:
        raise _Bad(key, f"is {value!r}, expected a non-empty text")


def _finite(value: Any, key: str, lo: float = -MAX_ABS, hi: float = MAX_ABS) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _Bad(key, f"is {value!r}, expected a number")
    number = float(value)
    if not math.isfinite(number) or not lo <= number <= hi:
        raise _Bad(key, f"is {value!r}, expected a finite number in [{lo:g}, {hi:g}]")
    return number


def _number(doc: dict[str, Any], key: str, lo: float = -MAX_ABS, hi: float = MAX_ABS) -> None:
    if key not in doc:
        raise _Bad(key, "is missing")
    _finite(doc[key], key, lo, hi)


def _box(box: Any) -> None:
    if not isinstance(box, dict):
        raise _Bad("box", f"is {box!r}, expected an object with center_m and extent_m")
    for key in ("center_m", "extent_m"):
        values = box.get(key)
        if not isinstance(values, list) or len(values) != 3:
            raise _Bad(f"box.{key}", f"is {values!r}, expected three numbers")
        for k, v in enumerate(values):
            _finite(v, f"box.{key}[{k}]", 0.0 if key == "extent_m" else -MAX_ABS)
    rotation = box.get("R")
    if rotation is not None:
        if not isinstance(rotation, list) or len(rotation) != 3 or any(
            not isinstance(row, list) or len(row) != 3 for row in rotation
        ):
            raise _Bad("box.R", "expected a 3x3 rotation matrix")
        for i, row in enumerate(rotation):
            for j, v in enumerate(row):
                _finite(v, f"box.R[{i}][{j}]", -1.0001, 1.0001)
