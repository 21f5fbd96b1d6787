"""perceive: runs refused before any write, full disks with committed frames kept."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.case import small_disk as _small_disk
from tests.faults.runner import Result, Workspace


def _perceived_twice(ws: Workspace) -> None:
    first = ws.hiper("perceive", "{log}", "--kb", "{root}/twice.hiper", "--detector", "truth", "--json")
    if first.returncode != 0:
        raise RuntimeError(first.stderr)
    shutil.rmtree(ws.kb)
    shutil.copytree(ws.root / "twice.hiper", ws.kb)

def _no_empty_session(ws: Workspace, result: Result) -> str | None:
    kb = ws.root / "new.hiper"
    if not (kb / "documents.sqlite").exists():
        return None
    info = ws.hiper("kb", "info", "--kb", str(kb), "--json")
    if info.returncode == 0 and json.loads(info.stdout)["sessions"]:
        return "a refused run left an (empty) session behind"
    return None

PERCEIVE = "perceive {log} --kb {root}/new.hiper --detector truth --json"

FULL_CAMERA = "--fx 210 --fy 210 --cx 127.5 --cy 95.5 --width 256 --height 192"


def cases() -> list[Case]:
    return [
        Case("perceive/same-log-again", "perceive", _argv("perceive {log} --kb {kb} --detector truth"),
             "error", "refused: offers --resume, --replace or --again", prepare=_perceived_twice,
             kb="consistent"),
        Case("perceive/detector-log-without-detections", "perceive", _argv(PERCEIVE.replace("truth", "log")),
             "error", "one line: the log holds no detections", kb=None, check=_no_empty_session),
        Case("perceive/unknown-class", "perceive", (*_argv(PERCEIVE), "--classes", "nosuchclass"), "error",
             "one line: unknown class", kb=None, check=_no_empty_session),
        Case("perceive/option-unknown-stage", "perceive", (*_argv(PERCEIVE), "-o", "nostage.x=1"), "usage",
             "one line: unknown stage", kb=None),
        Case("perceive/option-not-a-number", "perceive", (*_argv(PERCEIVE), "-o",
                                                          "foreground.pixel_step=abc"),
             "usage", "one line: expected an integer", kb=None, check=_no_empty_session),
        Case("perceive/option-unknown-key", "perceive", (*_argv(PERCEIVE), "-o", "foreground.pixel_stp=2"),
             "usage", "one line: did you mean pixel_step", kb=None, check=_no_empty_session),
        Case("perceive/option-nan", "perceive", (*_argv(PERCEIVE), "-o", "background.keyframe_hz=NaN"),
             "usage", "one line: not finite", kb=None, check=_no_empty_session),
        Case("perceive/mapping-hz-nan", "perceive", (*_argv(PERCEIVE), "--mapping-hz", "nan"), "usage",
             "one line: not finite", kb=None, check=_no_empty_session),
        Case("perceive/depth-scale-tiny", "perceive", (*_argv(PERCEIVE), "--depth-scale", "1e-300"), "usage",
             "one line: out of range", kb=None, check=_no_empty_session),
        Case("perceive/fx-huge", "perceive", (*_argv(PERCEIVE), *_argv(FULL_CAMERA.replace("210 --fy",
                                                                                           "1e308 --fy"))),
             "usage", "one line: out of range", kb=None, check=_no_empty_session),
        Case("perceive/cx-negative", "perceive", (*_argv(PERCEIVE), *_argv(FULL_CAMERA.replace("127.5",
                                                                                               "-1e9"))),
             "usage", "one line: out of range", kb=None, check=_no_empty_session),
        Case("perceive/max-dt-negative", "perceive", (*_argv(PERCEIVE), "--max-dt", "-1"), "usage",
             "one line: out of range", kb=None, check=_no_empty_session),
        Case("perceive/file-size-limit", "perceive",
             _argv("perceive {log} --kb {root}/new.hiper --detector truth"),
             "error", "disk full: one line, committed frames kept", kb=None, fsize_limit=600_000,
             check=lambda ws, r: "; ".join(_kb_ok(ws, ws.root / "new.hiper"))),
        Case("perceive/disk-full", "perceive",
             _argv("perceive {log} --kb {root}/small/k.hiper --detector truth"),
             "error", "disk full: one line, committed frames kept", kb=None, prepare=_small_disk,
             fsize_limit=None if os.geteuid() == 0 else 400_000,
             check=lambda ws, r: "; ".join(_kb_ok(ws, ws.root / "small" / "k.hiper"))),
    ]


def _kb_ok(ws: Workspace, kb: Path) -> list[str]:
    """After a full disk: once there is space again (a copy elsewhere), the knowledge base
    opens consistent (the graph may have lagged the documents for want of space)."""
    from tests.faults.runner import kb_problems

    if not (kb / "documents.sqlite").exists():
        return []
    copy = ws.root / "space-again.hiper"
    shutil.copytree(kb, copy)
    return kb_problems(ws.repo, copy, ws.root, None)
