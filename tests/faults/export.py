"""Exports: refused targets, full disks, the earlier export kept, valid XML."""

from __future__ import annotations

import os
import shutil

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.case import small_disk as _small_disk
from tests.faults.runner import Result, Workspace


def _earlier_export(ws: Workspace) -> None:
    shutil.copy(ws.cache / "export.json", ws.root / "out.json")

def _keeps_earlier_export(ws: Workspace, result: Result) -> str | None:
    if inputs.file_digest(ws.root / "out.json") != inputs.file_digest(ws.cache / "export.json"):
        return "lost: the earlier export was overwritten by a failed one"
    leftovers = [p.name for p in ws.root.iterdir() if p.name not in ("out.json", "scene.hiper")]
    return f"left behind: {leftovers}" if leftovers else None

def _earlier_export_on_small_disk(ws: Workspace) -> None:
    _small_disk(ws)
    shutil.copy(ws.cache / "export.json", ws.root / "small" / "out.json")

def _keeps_earlier_small_export(ws: Workspace, result: Result) -> str | None:
    if inputs.file_digest(ws.root / "small" / "out.json") != inputs.file_digest(ws.cache / "export.json"):
        return "lost: the earlier export was overwritten by a failed one"
    leftovers = [p.name for p in (ws.root / "small").iterdir() if p.name != "out.json"]
    return f"left behind: {leftovers}" if leftovers else None

def _control_char_env(ws: Workspace) -> None:
    data = inputs.export_doc(environments=[{"uuid": inputs.ENV_UUID, "name": "hall\x01\x0bway"}],
                             instances=[])
    inputs.write_json(ws.root / "in.json", data)
    result = ws.hiper("import", "{root}/in.json", "--kb", "{root}/ctl.hiper")
    if result.returncode != 0:
        raise RuntimeError(result.stderr)

def _graphml_reads_back(ws: Workspace, result: Result) -> str | None:
    import xml.etree.ElementTree as ET

    try:
        ET.parse(ws.root / "out.graphml")
    except (OSError, ET.ParseError) as err:
        return f"the GraphML file is not valid XML ({err})"
    return None


def cases() -> list[Case]:
    return [
        Case("export/over-own-database", "export",
             _argv("export {kb}/documents.sqlite --format json --kb {kb}"), "error",
             "refused: never writes inside a knowledge base"),
        Case("export/into-kb-folder", "export", _argv("export {kb}/x.json --kb {kb}"), "error",
             "refused: never writes inside a knowledge base"),
        Case("export/path-is-folder", "export", _argv("export {root} --format json --kb {kb}"), "error",
             "one line: the path is a folder"),
        Case("export/dev-full", "export", _argv("export /dev/full --format json --kb {kb}"), "error",
             "one line: no space left"),
        Case("export/file-size-limit", "export",
             _argv("export {root}/out.json --format json --observations --kb {kb}"), "error",
             "disk full half-way: one line, the earlier export kept", prepare=_earlier_export,
             check=_keeps_earlier_export, fsize_limit=200_000),
        Case("export/disk-full", "export",
             _argv("export {root}/small/out.json --format json --observations --kb {kb}"), "error",
             "no space half-way: one line, the earlier export kept", prepare=_earlier_export_on_small_disk,
             check=_keeps_earlier_small_export, fsize_limit=None if os.geteuid() == 0 else 150_000),
        Case("export/missing-folder", "export", _argv("export {root}/no/such/out.json --kb {kb}"), "ok",
             "creates the folder"),
        Case("export/unknown-format", "export", _argv("export {root}/out.xyz --kb {kb}"), "error",
             "one line: expected one of the formats"),
        Case("export/graphml-control-characters", "export",
             _argv("export {root}/out.graphml --kb {root}/ctl.hiper"), "ok",
             "valid XML: control characters escaped", prepare=_control_char_env, check=_graphml_reads_back),
    ]
