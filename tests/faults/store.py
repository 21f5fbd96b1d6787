"""The store: foreign or damaged databases, read-only media, mistyped --kb paths and schemes."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Callable

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.case import mount as _mount
from tests.faults.case import umount as _umount
from tests.faults.runner import Result, Workspace


def _foreign(ws: Workspace) -> None:
    shutil.rmtree(ws.kb, ignore_errors=True)
    inputs.foreign_sqlite(ws.kb)

def _damage_documents(ws: Workspace) -> None:
    inputs.damage_documents(ws.kb)

def _read_only(ws: Workspace) -> None:
    """The knowledge base on read-only media: a read-only bind mount when running as root
    (permissions do not stop root), else permission bits."""
    shutil.copytree(ws.cache / "template.hiper", ws.kb)
    if os.geteuid() == 0 and _mount("--bind", str(ws.kb), str(ws.kb)):
        subprocess.run(["mount", "-o", "remount,ro,bind", str(ws.kb)], check=True, capture_output=True)
        ws.cleanups.append(lambda: _umount(ws.kb))
        return
    inputs.make_read_only(ws.kb)
    ws.cleanups.append(lambda: [os.chmod(p, 0o755) for p in [ws.kb, *ws.kb.rglob("*")] if p.is_dir()])

def _opens(times: int) -> Callable[[Workspace, Result], str | None]:
    def check(ws: Workspace, result: Result) -> str | None:
        before = inputs.tree_bytes(ws.kb / "graph")
        for _ in range(times):
            ws.hiper("kb", "info", "--kb", "{kb}", "--json")
        grown = inputs.tree_bytes(ws.kb / "graph") - before
        return f"{times} opens grew the graph by {grown} bytes" if grown > 50_000 else None

    return check


def cases() -> list[Case]:
    cases = [
        Case("store/foreign-database-info", "store", _argv("kb info --kb {kb}"), "error",
             "refused read-only: not a hiper knowledge base, nothing written", prepare=_foreign,
            kb="unchanged"),
        Case("store/foreign-database-perceive", "store", _argv("perceive {log} --kb {kb} --detector truth"),
             "error", "refused before any write", prepare=_foreign, kb="unchanged"),
        Case("store/foreign-database-import", "store", _argv("import {export} --kb {kb}"), "error",
             "refused before any write", prepare=_foreign, kb="unchanged"),
        Case("store/damaged-documents-info", "store", _argv("kb info --kb {kb}"), "error",
             "one line: which file, sqlite3 .recover or the last export", prepare=_damage_documents,
             kb="unchanged"),
        Case("store/damaged-documents-check", "store", _argv("kb check --kb {kb}"), "error",
             "one line: which file, sqlite3 .recover or the last export", prepare=_damage_documents,
             kb="unchanged"),
        Case("store/check-mistyped-kb", "store", _argv("kb check --kb {root}/typo.hiper"), "error",
             "refused: no knowledge base there, nothing created", kb=None,
             check=lambda ws, r: "created a knowledge base" if (ws.root / "typo.hiper").exists() else None),
        Case("store/reanchor-mistyped-kb", "store",
             _argv("reanchor --kb {root}/typo.hiper --poses {log}/groundtruth.txt"), "error",
             "refused: no knowledge base there, nothing created", kb=None,
             check=lambda ws, r: "created a knowledge base" if (ws.root / "typo.hiper").exists() else None),
        Case("store/kb-is-a-file", "store", _argv("kb info --kb {log}/rgb.txt"), "error",
             "one line: a file, not a knowledge base", kb=None),
        Case("store/read-only-kb-info", "store", _argv("kb info --kb {kb}"), "ok",
             "opened read-only, read", prepare=_read_only, kb=None),
        Case("store/read-only-kb-export", "store", _argv("export {root}/out.json --kb {kb}"), "ok",
             "opened read-only, exported", prepare=_read_only, kb=None),
        Case("store/read-only-kb-perceive", "store", _argv("perceive {log} --kb {kb} --detector truth"),
             "error", "one line: the knowledge base is read-only", prepare=_read_only, kb=None),
        Case("store/repeated-opens", "store", _argv("kb info --kb {kb}"), "ok",
             "opening does not grow the graph folder", check=_opens(10)),
    ]
    for scheme in ("ftp://example.org/kb", "HTTP://", "file:///tmp/kb", "s3://bucket/kb"):
        cases.append(Case(f"store/kb-scheme-{scheme.split(':')[0].lower()}", "store",
                          ("kb", "info", "--kb", scheme), "error",
                          "refused: not a folder or http(s) endpoint, no local folder", kb=None,
                          check=lambda ws, r: f"created {list(ws.root.iterdir())}" if any(ws.root.iterdir())
                          else None))
    return cases
