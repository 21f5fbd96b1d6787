"""Which kind of log a path is, from its name and layout: nothing is read from it."""

from __future__ import annotations

from pathlib import Path

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.tum import is_tum_folder

__all__ = ["detect_format"]


def detect_format(path: Path) -> str:
    """``tum``, ``rosbag1``, ``rosbag2`` or ``mcap``; ``LogError`` when it is none of them."""
    if not path.exists():
        raise LogError(f"{path}: no such file or folder; pass a TUM folder, a .bag, a rosbag2 folder "
                       "or an .mcap file")
    if path.is_dir():
        if is_tum_folder(path):
            return "tum"
        if (path / "metadata.yaml").is_file():
            return "rosbag2"
        raise LogError(f"{path}: not a log folder (no rgb.txt or associations.txt, no metadata.yaml); "
                       "expected a TUM RGB-D folder or a rosbag2 folder")
    suffix = path.suffix.lower()
    if suffix == ".bag":
        return "rosbag1"
    if suffix == ".mcap":
        return "mcap"
    if suffix == ".db3" and (path.parent / "metadata.yaml").is_file():
        return "rosbag2"
    raise LogError(f"{path}: unknown log type '{suffix or path.name}'; expected a TUM folder, .bag, "
                   "a rosbag2 folder or .mcap")
