"""The fault corpus: every way the issue tracker found to break hiper, as data.

A ``Case`` is one ``hiper`` command line (``{kb}``, ``{log}``, ``{root}``, ``{export}``,
``{mcap}``, ``{bag}`` are filled from the case's workspace), what to do to the workspace first,
what it must end in (``expect``: ok, error or usage) and what the knowledge base must look like
after it (``kb``: intact = same documents and ``kb check --no-repair`` passes; consistent =
check passes; unchanged = not one file touched; absent = never created; repairable = ``kb
check`` rebuilds what the case damaged, then intact; None = no knowledge base involved).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.faults import inputs
from tests.faults.runner import Result, Workspace


@dataclass(frozen=True)
class Case:
    name: str
    group: str
    argv: tuple[str, ...]
    expect: str  # ok | error | usage | any (ok or a clean error)
    behaviour: str
    prepare: Callable[[Workspace], None] | None = None
    kb: str | None = "intact"
    check: Callable[[Workspace, Result], str | None] | None = None
    fsize_limit: int | None = None
    timeout_s: float = 90.0


def _argv(text: str) -> tuple[str, ...]:
    return tuple(text.split())


# -- preparations ----------------------------------------------------------------------------


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


def _write_import(name: str, data: Any) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        inputs.write_json(ws.root / "in.json", data)

    prepare.__name__ = f"import_{name}"
    return prepare


def _deep(ws: Workspace) -> None:
    inputs.deep_nesting(ws.root / "in.json")


def _foreign(ws: Workspace) -> None:
    shutil.rmtree(ws.kb, ignore_errors=True)
    inputs.foreign_sqlite(ws.kb)


def _damage_graph(how: str) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        inputs.damage_graph(ws.kb, how)

    return prepare


def _damage_documents(ws: Workspace) -> None:
    inputs.damage_documents(ws.kb)


def _log_copy(ws: Workspace) -> Path:
    return inputs.copy_log(ws.root / "log")


def _binary(name: str) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        inputs.binary_file(_log_copy(ws) / name)

    return prepare


def _huge_png(ws: Workspace) -> None:
    log = _log_copy(ws)
    first = sorted((log / "rgb").iterdir())[10]  # not the first: that one is also read to check sizes
    cached = ws.cache / "huge.png"
    if not cached.is_file():
        inputs.huge_png(cached)
    shutil.copy(cached, first)


def _damaged_bag(name: str, seed: int = 7) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        source = ws.cache / name
        target = ws.root / name
        if source.is_dir():
            shutil.copytree(source, target)
            files = [p for p in target.rglob("*.mcap")]
        else:
            shutil.copy(source, target)
            files = [target]
        inputs.damage_middle(files[0], 200_000, seed)

    return prepare


def _fresh_kb(ws: Workspace) -> None:
    shutil.rmtree(ws.kb, ignore_errors=True)


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


def _small_disk(ws: Workspace) -> None:
    """A 900 KB file system at ``{root}/small`` (root only; elsewhere the case is limited by
    RLIMIT_FSIZE instead)."""
    small = ws.root / "small"
    small.mkdir()
    if os.geteuid() == 0 and _mount("-t", "tmpfs", "-o", "size=900k", "tmpfs", str(small)):
        ws.cleanups.append(lambda: _umount(small))


def _mount(*args: str) -> bool:
    return subprocess.run(["mount", *args], capture_output=True).returncode == 0


def _umount(path: Path) -> None:
    subprocess.run(["umount", "-l", str(path)], capture_output=True)


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


def _opens(times: int) -> Callable[[Workspace, Result], str | None]:
    def check(ws: Workspace, result: Result) -> str | None:
        before = inputs.tree_bytes(ws.kb / "graph")
        for _ in range(times):
            ws.hiper("kb", "info", "--kb", "{kb}", "--json")
        grown = inputs.tree_bytes(ws.kb / "graph") - before
        return f"{times} opens grew the graph by {grown} bytes" if grown > 50_000 else None

    return check


def _confidence_zero_kept(ws: Workspace, result: Result) -> str | None:
    out = ws.hiper("export", "{root}/back.json", "--kb", "{root}/zero.hiper", "--format", "json")
    if out.returncode != 0:
        return f"export failed: {out.stderr.strip()[-200:]}"
    data = json.loads((ws.root / "back.json").read_text())
    confidences = [i["confidence"] for i in data["instances"]]
    return None if confidences == [0.0] else f"confidence 0.0 came back as {confidences}"


def _perceived_twice(ws: Workspace) -> None:
    first = ws.hiper("perceive", "{log}", "--kb", "{root}/twice.hiper", "--detector", "truth", "--json")
    if first.returncode != 0:
        raise RuntimeError(first.stderr)
    shutil.rmtree(ws.kb)
    shutil.copytree(ws.root / "twice.hiper", ws.kb)


def _mcap_not_silent(ws: Workspace, result: Result) -> str | None:
    if result.returncode != 0:
        return None
    data = json.loads(result.stdout)
    frames = sum(1 for line in (inputs.FIXTURE / "rgb.txt").read_text().splitlines()
                 if line.strip() and not line.startswith("#"))
    if data["frames_read"] + data["frames_skipped"] < frames:
        return (f"lost: {frames - data['frames_read']} of {frames} frames not read but "
                f"{data['frames_skipped']} reported skipped")
    return None


def _no_empty_session(ws: Workspace, result: Result) -> str | None:
    kb = ws.root / "new.hiper"
    if not (kb / "documents.sqlite").exists():
        return None
    info = ws.hiper("kb", "info", "--kb", str(kb), "--json")
    if info.returncode == 0 and json.loads(info.stdout)["sessions"]:
        return "a refused run left an (empty) session behind"
    return None


# -- the corpus -------------------------------------------------------------------------------

PERCEIVE = "perceive {log} --kb {root}/new.hiper --detector truth --json"
FULL_CAMERA = "--fx 210 --fy 210 --cx 127.5 --cy 95.5 --width 256 --height 192"


def _usage() -> list[Case]:
    rows = [
        ("unknown-command", "nosuch", "usage line, 'no such command', exit 2"),
        ("unknown-command-typo", "perceve", "usage line, did you mean 'perceive', exit 2"),
        ("unknown-option", "perceive --nosuch {log}", "usage line, 'no such option', exit 2"),
        ("option-typo", "perceive --stage background {log}", "did you mean '--stages', exit 2"),
        ("missing-argument", "info", "usage line, 'missing argument', exit 2"),
        ("unknown-subcommand", "kb chek", "did you mean 'check', exit 2"),
        ("not-a-number", "sim --seed abc --out {root}/sim", "invalid value for --seed, exit 2"),
    ]
    return [Case(f"usage/{n}", "usage", _argv(a), "usage", b, kb=None) for n, a, b in rows]


def _export() -> list[Case]:
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


def _imports() -> list[Case]:
    cases = [
        Case(f"import/{name}", "import", _argv("import {root}/in.json --format json --kb {kb}"), "error",
             "refused before any write, naming the document and field", prepare=_write_import(name, data))
        for name, data in inputs.HOSTILE_IMPORTS.items()
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


def _store() -> list[Case]:
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
    for how in ("sst", "current", "manifest", "file"):
        cases.append(Case(f"graph/damaged-{how}-check", "graph", _argv("kb check --kb {kb}"), "ok",
                          "kb check rebuilds the scene graph from the documents",
                          prepare=_damage_graph(how)))
        cases.append(Case(f"graph/damaged-{how}-info", "graph", _argv("kb info --kb {kb}"), "any",
                          "read from the documents or one line: run 'hiper kb check'",
                          prepare=_damage_graph(how), kb="repairable"))
    cases.append(Case("graph/damaged-export", "graph", _argv("export {root}/out.ttl --kb {kb}"), "error",
                      "one line: run 'hiper kb check' to rebuild the graph", prepare=_damage_graph("sst"),
                      kb="repairable"))
    return cases


def _perceive() -> list[Case]:
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


def _logs() -> list[Case]:
    log = "perceive {root}/log --kb {root}/new.hiper --detector truth --json"
    return [
        Case("logs/binary-rgb-list", "logs", _argv(log), "error", "one line naming rgb.txt",
             prepare=_binary("rgb.txt"), kb=None),
        Case("logs/binary-associations", "logs", _argv(log), "error", "one line naming associations.txt",
             prepare=_binary("associations.txt"), kb=None),
        Case("logs/binary-detections", "logs", _argv(log.replace("truth", "log")), "error",
             "one line naming detections.jsonl", prepare=_binary("detections.jsonl"), kb=None),
        Case("logs/binary-groundtruth", "logs", _argv(log), "error", "one line naming groundtruth.txt",
             prepare=_binary("groundtruth.txt"), kb=None),
        Case("logs/huge-png", "logs", _argv(log), "any",
             "image size checked before decoding: skipped or one line", prepare=_huge_png, kb=None,
             timeout_s=60.0),
        *(Case(f"logs/mcap-damaged-{seed}", "logs",
               _argv("perceive {root}/log.mcap --kb {root}/new.hiper --stages background --json"), "any",
               "damage counted as skipped frames or one line", prepare=_damaged_bag("log.mcap", seed),
               kb=None, check=_mcap_not_silent) for seed in (3, 4, 7)),
        Case("logs/rosbag1-damaged", "logs",
             _argv("perceive {root}/log.bag --kb {root}/new.hiper --stages background --json"), "any",
             "damage counted as skipped frames or one line", prepare=_damaged_bag("log.bag"), kb=None,
             check=_mcap_not_silent),
        Case("logs/missing", "logs", _argv("perceive {root}/nolog --kb {root}/new.hiper"), "error",
             "one line: no such log", kb=None),
        Case("logs/convert-missing-folder", "logs", _argv("convert {log} {root}/no/such/x.bag --to rosbag1"),
             "any", "creates the folder or one line", kb=None),
        Case("logs/convert-onto-existing", "logs", _argv("convert {log} {bag} --to rosbag1"), "error",
             "refused: never overwrites a bag", kb=None),
    ]


def _options() -> list[Case]:
    sim = "sim --out {root}/sim --seconds 2 --width 64 --height 48"
    rows = [
        ("sim-seconds-inf", sim.replace("--seconds 2", "--seconds inf")),
        ("sim-seconds-negative", sim.replace("--seconds 2", "--seconds -5")),
        ("sim-rate-nan", sim + " --rate-hz nan"),
        ("sim-seed-negative", sim + " --seed -1"),
        ("sim-width-huge", sim.replace("--width 64", "--width 1000000")),
        ("sim-false-positives-huge", sim + " --false-positives 1e9"),
        ("sim-miss-rate-above-one", sim + " --miss-rate 2"),
        ("sim-png-compression", sim + " --png-compression 12"),
        ("eval-max-frames-negative", "eval foreground {log} --max-frames -1"),
        ("bench-obs-per-frame-zero", "kb bench --sizes 100 --obs-per-frame 0"),
        ("bench-queries-negative", "kb bench --sizes 100 --queries -3"),
        ("bench-sync-nan", "kb bench --sizes 100 --graph-sync-s nan"),
        ("reanchor-max-dt-inf", "reanchor --kb {kb} --poses {log}/groundtruth.txt --max-dt-s inf"),
    ]
    return [Case(f"options/{n}", "options", _argv(a), "usage", "one line naming the option and its range",
                 kb=None, timeout_s=30.0) for n, a in rows]


def all_cases() -> list[Case]:
    return [*_usage(), *_export(), *_imports(), *_store(), *_perceive(), *_logs(), *_options()]


KILL_KINDS = ("perceive", "export", "import")
KILLS_PER_KIND = 20
