"""Imports: hostile documents refused before any write, the knowledge base left as it was."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.runner import Result, Workspace


def _write_import(name: str, data: Any) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        inputs.write_json(ws.root / "in.json", data)

    prepare.__name__ = f"import_{name}"
    return prepare

def _deep(ws: Workspace) -> None:
    inputs.deep_nesting(ws.root / "in.json")

def _confidence_zero_kept(ws: Workspace, result: Result) -> str | None:
    out = ws.hiper("export", "{root}/back.json", "--kb", "{root}/zero.hiper", "--format", "json")
    if out.returncode != 0:
        return f"export failed: {out.stderr.strip()[-200:]}"
    data = json.loads((ws.root / "back.json").read_text())
    confidences = [i["confidence"] for i in data["instances"]]
    return None if confidences == [0.0] else f"confidence 0.0 came back as {confidences}"


def _edited_export(edit: Callable[[dict[str, Any]], Any]) -> Callable[[Workspace], None]:
    """The template's own JSON export with one field changed by ``edit`` (which may return the
    file's text, for what ``json.dumps`` cannot write: NaN, a huge integer)."""
    def prepare(ws: Workspace) -> None:
        data = json.loads((ws.cache / "export.json").read_text())
        text = edit(data)
        (ws.root / "in.json").write_text(text if isinstance(text, str) else json.dumps(data))

    return prepare


def _first(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def edit(data: dict[str, Any]) -> None:
        data["instances"][0][key] = value

    return edit


def _raw(old: str, new: str) -> Callable[[dict[str, Any]], str]:
    def edit(data: dict[str, Any]) -> str:
        text = json.dumps(data)
        assert old in text, old
        return text.replace(old, new, 1)

    return edit


def _uuid_of_environment(data: dict[str, Any]) -> None:
    data["instances"][0]["uuid"] = data["environments"][0]["uuid"]


def _uuid_of_stored_environment(data: dict[str, Any]) -> None:
    """A new export (its own environment) whose instance takes the stored environment's uuid."""
    stored_env = data["environments"][0]["uuid"]
    data["environments"] = [{"uuid": inputs.ENV_UUID, "name": "elsewhere"}]
    data["instances"] = [{**data["instances"][0], "uuid": stored_env}]
    data["observations"] = []


# the second probe's reproducers: each was written, then broke the graph sync or a reader
EDITED_EXPORTS: dict[str, Callable[[dict[str, Any]], Any]] = {
    "vacated-text": _first("vacated_s", "yesterday"),
    "data-vacated-text": _first("data", {"vacated_s": "x"}),
    "frame-object": _first("frame", {"a": 1}),
    "uuid-of-environment": _uuid_of_environment,
    "uuid-of-stored-environment": _uuid_of_stored_environment,
    "vacated-nan": _raw('"vacated_s": null', '"vacated_s": NaN'),
    "data-list": _first("data", [1, 2]),
    "data-text": _first("data", "abc"),
    "data-number": _first("data", 5),
    "coordinate-huge": _raw('"center_m": [', '"center_m": [1' + "0" * 400 + ", "),
    "class-lone-surrogate": _raw('"class": "', '"class": "\\ud800'),
    "class-too-long": _first("class", "x" * 5000),
    "last-seen-text": _first("last_seen_s", "noon"),
    "observation-uuids-not-uuids": _first("observation_uuids", ["x"]),
}


def cases() -> list[Case]:
    cases = [
        Case(f"import/{name}", "import", _argv("import {root}/in.json --format json --kb {kb}"), "error",
             "refused before any write, naming the document and field", prepare=_write_import(name, data),
             kb="unchanged")
        for name, data in inputs.HOSTILE_IMPORTS.items()
    ]
    cases += [
        Case(f"import/{name}", "import", _argv("import {root}/in.json --kb {kb}"), "error",
             "refused before any write, naming the field; the KB byte-for-byte as it was (then kb check)",
             prepare=_edited_export(edit), kb="unchanged", check=_still_checks)
        for name, edit in EDITED_EXPORTS.items()
    ]
    cases += [
        Case("import/deep-nesting", "import", _argv("import {root}/in.json --format json --kb {kb}"), "error",
             "refused: too deeply nested", prepare=_deep),
        Case("import/binary-file", "import", _argv("import {root}/in.json --format json --kb {kb}"), "error",
             "refused: not JSON", prepare=lambda ws: inputs.binary_file(ws.root / "in.json") and None),
        Case("import/missing-file", "import", _argv("import {root}/none.json --kb {kb}"), "error",
             "one line: file missing"),
        Case("import/confidence-zero", "import", _argv("import {root}/in.json --kb {root}/zero.hiper"), "ok",
             "confidence 0.0 survives the round trip", prepare=_write_import("valid", inputs.export_doc()),
             check=_confidence_zero_kept, kb=None),
        Case("import/into-itself", "import", _argv("import {kb}/documents.sqlite --format json --kb {kb}"),
             "error", "refused: not a hiper export"),
    ]
    return cases


def _still_checks(ws: Workspace, result: Result) -> str | None:
    """After a refused import the knowledge base still opens, exports and passes kb check."""
    from tests.faults.runner import kb_problems

    problems = kb_problems(ws.repo, ws.kb, ws.root, None)
    out = ws.hiper("export", "{root}/after.json", "--kb", "{kb}")
    if out.returncode != 0:
        problems.append(f"export after the refused import failed: {out.stderr.strip()[-200:]}")
    return "; ".join(problems) or None
