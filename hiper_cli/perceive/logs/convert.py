"""Copy a sensor log into another format: TUM folder, rosbag1, rosbag2 (sqlite3) or MCAP."""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError, LogError
from hiper_cli.files import os_error, refuse_inside
from hiper_cli.perceive.logs import LogReader
from hiper_cli.perceive.logs.bag_writer import BAG_KINDS, BagLayout, BagWriter
from hiper_cli.perceive.logs.tum_writer import TumWriter
from hiper_cli.types import Frame

__all__ = ["CONVERT_TARGETS", "ConvertResult", "bag_layout", "convert_log"]

CONVERT_TARGETS = ("tum", *BAG_KINDS)
TUM_DEPTH_SCALE = 5000.0  # TUM RGB-D convention: depth PNG units per metre


@dataclass(frozen=True)
class ConvertResult:
    output: str
    to: str
    frames_written: int
    skipped: list[tuple[str, str]] = field(default_factory=list)
    input: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"input": self.input, "output": self.output, "to": self.to,
                "frames_written": self.frames_written,
                "skipped": [{"source": s, "reason": r} for s, r in self.skipped]}


_CHOICES = {"--rgb-format": ("raw", "png", "jpeg"), "--depth-encoding": ("16UC1", "32FC1"),
            "--pose-as": ("tf", "odometry", "pose")}
_POSE_TOPICS = {"tf": "/tf", "odometry": "/odom", "pose": "/pose"}


def bag_layout(to: str, rgb_format: str = "raw", depth_encoding: str = "16UC1",
               pose_as: str = "tf") -> BagLayout:
    """The ``BagLayout`` for these choices (the ``hiper convert`` flags), each checked by name."""
    given = {"--to": (to, CONVERT_TARGETS), **{flag: (value, _CHOICES[flag]) for flag, value in
             (("--rgb-format", rgb_format), ("--depth-encoding", depth_encoding), ("--pose-as", pose_as))}}
    for flag, (value, allowed) in given.items():
        if value not in allowed:
            raise ConfigError(f"{flag} {value}: unknown; expected one of {', '.join(allowed)}")
    return BagLayout(rgb_format=rgb_format, depth_encoding=depth_encoding, pose_as=pose_as,  # type: ignore[arg-type]
                     pose_topic=_POSE_TOPICS[pose_as])


def convert_log(reader: LogReader, out: str | Path, to: str, *, layout: BagLayout | None = None,
                overwrite: bool = False, on_frame: Callable[[Frame], None] | None = None,
                rgb_jpeg_quality: int | None = None) -> ConvertResult:
    """Write every readable frame of ``reader`` (a ``LogReader``) to ``out`` in format ``to``.

    ``layout`` sets the bag topics, frames and encodings; ``overwrite`` lets a TUM output
    reuse a non-empty folder (bags are never overwritten). TUM output stores depth at
    5000 units per metre (the TUM convention; depths beyond 13.1 m become invalid) and colour as
    PNG, or as JPEG at ``rgb_jpeg_quality``.
    """
    if to not in CONVERT_TARGETS:
        raise ConfigError(f"--to {to}: unknown format; expected one of {', '.join(CONVERT_TARGETS)}")
    out = Path(out)
    refuse_inside(out, "converted log")
    info = reader.info()
    source, target = Path(info.path).resolve(), out.resolve()
    if target == source or source in target.parents or target in source.parents:
        raise ConfigError(f"{out}: the output is the input log {info.path} (or holds it, or lies in it); "
                          "choose an output path outside the log")
    if out.exists() and (to != "tum" or not overwrite):
        if to != "tum":
            raise LogError(f"{out}: exists already; choose a new output path")
        if out.is_file() or any(out.iterdir()):
            raise LogError(f"{out}: folder exists and is not empty; choose another output or pass "
                           "--overwrite")
    camera = info.camera
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise os_error(out.parent, err, "create") from err
    # written beside the target and renamed into place when complete: a failure half-way
    # leaves nothing (or the earlier folder) behind
    partial = out.parent / f".{out.name}.{os.getpid()}.partial"
    _remove(partial)
    writer: TumWriter | BagWriter
    written = 0
    try:
        if to == "tum":
            writer = TumWriter(partial, replace(camera, depth_scale=TUM_DEPTH_SCALE),
                               rgb_jpeg_quality=rgb_jpeg_quality)
        else:
            writer = BagWriter(partial, to, camera, layout or BagLayout())
        with writer:
            for frame in reader:
                writer.write(frame)
                written += 1
                if on_frame is not None:
                    on_frame(frame)
        _move_into_place(partial, out)
    except OSError as err:
        raise os_error(out, err) from err
    finally:
        _remove(partial)
    return ConvertResult(str(out), to, written, list(reader.skipped), input=str(reader.info().path))


def _remove(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    elif path.exists():
        path.unlink()


def _move_into_place(partial: Path, out: Path) -> None:
    """Rename ``partial`` to ``out``; an existing (``--overwrite``) folder is swapped out first."""
    if not out.exists():
        os.replace(partial, out)
        return
    old = out.parent / f".{out.name}.{os.getpid()}.old"
    os.replace(out, old)
    os.replace(partial, out)
    _remove(old)
