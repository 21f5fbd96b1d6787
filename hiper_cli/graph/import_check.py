"""Validate imported documents before anything is written: a bad one names its place and field.

An import must not save what later breaks the knowledge base (a uuid that is no IRI, a layer
the graph has no named graph for, a box of text, a stamp of ``inf``). ``check_documents`` gets
``(where, document)`` pairs in their ``to_dict`` form, ``where`` saying where in the source the
document came from (``instances[3]``, ``node <urn:uuid:...>``), and raises ``DataError`` at the
first problem. A JSON export is read strictly first (``read_json_export``: no NaN or Infinity,
no lone surrogates, no nesting deeper than an export has) and checked in full against
``export.schema.json``; ``check_unique`` refuses one uuid used for two documents.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hiper_cli.errors import DataError

__all__ = ["check_documents", "check_json_shape", "check_unique", "read_json_export"]

MAX_DEPTH = 64  # an export nests a few levels (instances[k].box.R[i][j]); more is no export

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


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _walk_strings(value: Any, where: str, depth: int = 0) -> None:
    """Refuse nesting beyond ``MAX_DEPTH`` and strings that are not valid Unicode text."""
    if depth > MAX_DEPTH:
        raise DataError(f"{where}: nested deeper than {MAX_DEPTH} levels")
    if isinstance(value, str):
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:
            raise DataError(f"{where}: {value[:40]!r} holds a lone surrogate (\\ud800-\\udfff), "
                            "not text") from None
    elif isinstance(value, dict):
        for k, v in value.items():
            _walk_strings(k, where, depth + 1)
            _walk_strings(v, f"{where}.{k}", depth + 1)
    elif isinstance(value, list):
        for k, v in enumerate(value):
            _walk_strings(v, f"{where}[{k}]", depth + 1)


def read_json_export(path: Path) -> dict[str, Any]:
    """A JSON export read strictly and checked in full against ``export.schema.json``;
    ``DataError`` naming the place and the problem otherwise."""
    import json

    try:
        data = json.loads(path.read_text(encoding="utf-8"), parse_constant=_no_constant)
    except (ValueError, RecursionError) as err:  # RecursionError: nesting deeper than any export
        detail = "nested too deeply" if isinstance(err, RecursionError) else " ".join(str(err).split())[:200]
        raise DataError(f"{path}: not valid JSON ({detail}); pass a file written by "
                        "'hiper export --format json'") from err
    except OSError as err:
        raise DataError(f"{path}: cannot read it ({err.strerror})") from err
    try:
        _walk_strings(data, "$")
    except DataError as err:
        raise DataError(f"{path}: {err}; nothing was imported") from None
    check_json_shape(data, path)
    if data.get("format") != "hiper-kb-export":
        raise DataError(f"{path}: not a hiper JSON export (format {data.get('format')!r}); expected "
                        "'hiper-kb-export' written by 'hiper export --format json'")
    _check_schema(data, path)
    export: dict[str, Any] = data
    return export


def _check_schema(data: Any, path: Path) -> None:
    import json
    from importlib import resources

    import jsonschema
    from jsonschema.exceptions import best_match

    schema = json.loads(resources.files("hiper_cli.graph").joinpath("export.schema.json").read_text())
    error = best_match(jsonschema.Draft202012Validator(schema).iter_errors(data))
    if error is None:
        return
    where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.absolute_path).lstrip(".")
    value = repr(error.instance)
    value = value if len(value) <= 60 else value[:57] + "..."
    causes = error.context or [error]  # oneOf: what each alternative wanted
    wanted = dict.fromkeys(" ".join(c.message.replace(repr(c.instance), "it").split()) for c in causes)
    not_uuid = f"does not match {UUID_RE.pattern!r}"
    problem = " or ".join(wanted).replace(not_uuid, "is not a uuid (8-4-4-4-12 hex digits)")
    problem = problem if len(problem) <= 160 else problem[:157] + "..."
    raise DataError(f"{path}: {where or 'the top level'}: {value}: {problem}; nothing was imported, fix "
                    "or remove that document")


def check_unique(docs: Sequence[tuple[str, dict[str, Any]]], source: Path,
                 existing_type: Any = None) -> None:
    """One uuid names one document: refuse two documents of an import with one uuid, and
    (``existing_type(uuid)``: the type a stored document of that uuid has, or None) a
    document whose uuid the knowledge base already uses for another type."""
    seen: dict[str, str] = {}
    for where, doc in docs:
        uuid, kind = str(doc.get("uuid")), doc.get("type")
        if uuid in seen:
            raise DataError(f"{source}: {where}: uuid {uuid!r} is also {seen[uuid]}; nothing was "
                            "imported, give each document its own uuid")
        seen[uuid] = where
        stored = existing_type(uuid) if existing_type is not None else None
        if stored is not None and stored != kind:
            raise DataError(f"{source}: {where}: uuid {uuid!r} is a stored {stored} of the knowledge "
                            f"base, not a {kind}; nothing was imported, give it its own uuid")


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
    if doc.get("frame_id") is not None:
        _text(doc, "frame_id")
    data = doc.get("data", {})
    if isinstance(data, dict) and data.get("vacated_s") is not None:
        _finite(data["vacated_s"], "data.vacated_s")
    if isinstance(data, dict) and data.get("same_object_as") is not None:
        try:
            _uuid(data, "same_object_as")
        except _Bad as bad:
            raise _Bad("data.same_object_as", bad.problem) from None
    if kind == "environment":
        _text(doc, "name")
    elif kind in ("instance", "observation"):
        _perceived(doc, kind)
    elif kind == "analysis":
        _analysis(doc)
    elif kind == "change":
        _change(doc)
    else:
        raise _Bad("type", f"is {kind!r}, expected environment, instance, observation, analysis or change")


def _perceived(doc: dict[str, Any], kind: str) -> None:
    """An instance or an observation: layer, class, box, confidence, then its own fields."""
    if doc.get("layer") not in PERCEIVED_LAYERS:
        raise _Bad("layer", f"is {doc.get('layer')!r}, expected one of {', '.join(PERCEIVED_LAYERS)}")
    _text(doc, "class")
    _box(doc.get("box"))
    _number(doc, "confidence", 0.0, 1.0)
    if kind == "instance":
        _instance(doc)
    else:
        _observation(doc)
    if not isinstance(doc.get("data", {}), dict):
        raise _Bad("data", "is not an object")


def _instance(doc: dict[str, Any]) -> None:
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


def _observation(doc: dict[str, Any]) -> None:
    _number(doc, "stamp_s")
    if not isinstance(doc.get("pose_id", -1), int) or isinstance(doc.get("pose_id"), bool):
        raise _Bad("pose_id", f"is {doc.get('pose_id')!r}, expected an integer")
    if doc.get("instance_uuid") is not None:
        _uuid(doc, "instance_uuid")


def _analysis(doc: dict[str, Any]) -> None:
    _text(doc, "kind")
    if doc.get("class") is not None:
        _text(doc, "class")
    for key in ("t_start_s", "t_end_s", "created_s"):
        _number(doc, key)
    if not isinstance(doc.get("values"), dict):
        raise _Bad("values", "is not an object")


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
    if not isinstance(value, str) or not value or len(value) > 1000:
        raise _Bad(key, f"is {str(value)[:60]!r}, expected a non-empty text of at most 1000 characters")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise _Bad(key, "holds a lone surrogate, not text") from None


def _finite(value: Any, key: str, lo: float = -MAX_ABS, hi: float = MAX_ABS) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _Bad(key, f"is {str(value)[:60]!r}, expected a number")
    if isinstance(value, int) and abs(value) > hi:
        raise _Bad(key, f"is {str(value)[:20]}..., expected a finite number in [{lo:g}, {hi:g}]")
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
