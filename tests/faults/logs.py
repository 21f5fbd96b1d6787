"""Damaged logs: binary lists, huge images, damaged bags; damage is a skipped frame or one line."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.runner import Result, Workspace


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


def cases() -> list[Case]:
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
        *_second_probe(log),
    ]


# -- the second probe (issue 58): list paths, poses, camera.json, truncated JPEGs ---------------


def _edit_line(name: str, number: int, edit: Callable[[str], str]) -> Callable[[Workspace], None]:
    """A copy of the log with line ``number`` (counting data lines from 0) of ``name`` edited."""
    def prepare(ws: Workspace) -> None:
        log = _log_copy(ws)
        lines = (log / name).read_text().splitlines()
        data = [k for k, line in enumerate(lines) if line.strip() and not line.startswith("#")]
        lines[data[number]] = edit(lines[data[number]])
        (log / name).write_text("\n".join(lines) + "\n")

    return prepare


def _image_path(path: str) -> Callable[[str], str]:
    return lambda line: f"{line.split()[0]} {path}"


def _camera(text: str | Callable[[dict[str, Any]], None]) -> Callable[[Workspace], None]:
    """A copy of the log whose camera.json is ``text``, or its own with ``text`` applied."""
    def prepare(ws: Workspace) -> None:
        log = _log_copy(ws)
        if isinstance(text, str):
            (log / "camera.json").write_text(text)
            return
        data = json.loads((log / "camera.json").read_text())
        text(data)
        (log / "camera.json").write_text(json.dumps(data))

    return prepare


def _setting(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    return lambda data: data.__setitem__(key, value)


def _jpeg_frames(truncate: bool) -> Callable[[Workspace], None]:
    """Frames 10 and 11 as JPEG files (frame 10 cut in half when ``truncate``)."""
    def prepare(ws: Workspace) -> None:
        import cv2

        log = _log_copy(ws)
        lines = (log / "rgb.txt").read_text().splitlines()
        data = [k for k, line in enumerate(lines) if line.strip() and not line.startswith("#")]
        for n, k in enumerate(data[10:12]):
            stamp, png = lines[k].split()
            _, buf = cv2.imencode(".jpg", cv2.imread(str(log / png)))
            jpeg = buf.tobytes()
            name = png.replace(".png", ".jpg")
            (log / name).write_bytes(jpeg[: len(jpeg) // 2] if truncate and n == 0 else jpeg)
            lines[k] = f"{stamp} {name}"
        (log / "rgb.txt").write_text("\n".join(lines) + "\n")

    return prepare


def _skipped(field: str, expected: int) -> Callable[[Workspace, Result], str | None]:
    def check(ws: Workspace, result: Result) -> str | None:
        if result.returncode != 0:
            return None
        data = json.loads(result.stdout)
        got = data[field] if field != "readable_frames" else data["frames"] - data["readable_frames"]
        return None if got == expected else f"{got} frames counted as damaged, expected {expected}"

    return check


def _second_probe(log: str) -> list[Case]:
    info = "info {root}/log --check --json"
    rows: list[Case] = [
        Case("logs/rgb-list-absolute-path", "logs", _argv(log), "error",
             "one line: rgb.txt:N lies outside the log",
             prepare=_edit_line("rgb.txt", 2, _image_path("/etc/passwd")), kb=None),
        Case("logs/rgb-list-parent-path", "logs", _argv(info), "error",
             "one line: rgb.txt:N lies outside the log",
             prepare=_edit_line("rgb.txt", 2, _image_path("../../../etc/passwd")), kb=None),
        Case("logs/depth-list-absolute-path", "logs", _argv(info), "error",
             "one line: depth.txt:N lies outside the log",
             prepare=_edit_line("depth.txt", 0, _image_path("/etc/hostname")), kb=None),
        Case("logs/pose-huge-perceive", "logs", _argv(log), "error",
             "one line: groundtruth.txt:N out of range",
             prepare=_edit_line("groundtruth.txt", 1, lambda line: line.replace(line.split()[1], "1e300", 1)),
             kb=None),
        Case("logs/pose-huge-info", "logs", _argv(info), "error", "one line: groundtruth.txt:N out of range",
             prepare=_edit_line("groundtruth.txt", 1, lambda line: line.replace(line.split()[1], "1e300", 1)),
             kb=None),
        Case("logs/camera-deep-nesting", "logs", _argv(info), "error", "one line: nested too deeply",
             prepare=_camera("[" * 100_000), kb=None),
        Case("logs/camera-not-an-object", "logs", _argv(info), "error", "one line: expected an object",
             prepare=_camera("[1, 2]"), kb=None),
        Case("logs/camera-nan", "logs", _argv(info), "error", "one line: NaN is no JSON number",
             prepare=_camera('{"width": 256, "height": 192, "fx": NaN, "fy": 210, "cx": 127.5, "cy": 95.5}'),
             kb=None),
    ]
    for key, value in (("fx", True), ("fx", 1e308), ("cx", 100000), ("cy", -1), ("width", 256.5),
                       ("height", "192"), ("depth_scale", 0), ("fy", None), ("distortion", "none")):
        rows.append(Case(f"logs/camera-{key}-{str(value).lower().replace('.', '_')}", "logs", _argv(info),
                         "error", f"one line: '{key}' is {value!r}, expected a number in range",
                         prepare=_camera(_setting(key, value)), kb=None))
    rows += [
        Case("logs/jpeg-truncated-info", "logs", _argv(info), "ok", "the truncated JPEG counted unreadable",
             prepare=_jpeg_frames(truncate=True), check=_skipped("readable_frames", 1), kb=None),
        Case("logs/jpeg-truncated-perceive", "logs", _argv(log), "ok", "the truncated JPEG a skipped frame",
             prepare=_jpeg_frames(truncate=True), check=_skipped("frames_skipped", 1), kb=None),
        Case("logs/jpeg-complete", "logs", _argv(info), "ok", "complete JPEGs all readable",
             prepare=_jpeg_frames(truncate=False), check=_skipped("readable_frames", 0), kb=None),
    ]
    return rows
