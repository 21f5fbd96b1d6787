"""TUM RGB-D folders: ``rgb.txt``, ``depth.txt``, ``groundtruth.txt`` (or an associations file).

Colour and depth images are associated by nearest timestamp within ``max_dt_s`` (as TUM's
``associate.py`` does: closest pairs first, each image used once), unless the folder holds
``associations.txt`` or ``assoc.txt`` (``t_rgb rgb_path t_depth depth_path`` per line).
A frame takes the colour image's stamp; its pose is ``groundtruth.txt`` (or the ``poses``
trajectory) interpolated to that stamp; frames outside the trajectory's time span are
skipped and counted. Intrinsics: ``camera`` argument, else ``camera.json`` in the folder,
else the Freiburg preset named by the folder (``rgbd_dataset_freiburg1_*`` ...).
An optional ``detections.jsonl`` (one line per image ``{"stamp_s", "detections": [...]}``)
gives ``Frame.detections``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.base import FrameEntry, IndexedLog
from hiper_cli.perceive.logs.images import read_depth_png, read_rgb_file
from hiper_cli.perceive.logs.trajectory import Trajectory, read_tum_trajectory
from hiper_cli.types import CameraIntrinsics, Detections

__all__ = ["TUM_PRESETS", "TumReader", "associate", "is_tum_folder", "load_camera_json", "open_tum",
           "tum_camera"]

# Freiburg calibrations published with the TUM RGB-D benchmark (depth factor 5000).
TUM_PRESETS: dict[str, CameraIntrinsics] = {
    "fr1": CameraIntrinsics(640, 480, 517.3, 516.5, 318.6, 255.3, 5000.0,
                            (0.2624, -0.9531, -0.0054, 0.0026, 1.1633)),
    "fr2": CameraIntrinsics(640, 480, 520.9, 521.0, 325.1, 249.7, 5000.0,
                            (0.2312, -0.7849, -0.0033, -0.0001, 0.9172)),
    "fr3": CameraIntrinsics(640, 480, 535.4, 539.2, 320.1, 247.6, 5000.0),
    "ros": CameraIntrinsics(640, 480, 525.0, 525.0, 319.5, 239.5, 5000.0),
}
ASSOCIATION_FILES = ("associations.txt", "assoc.txt")


def is_tum_folder(path: Path) -> bool:
    return path.is_dir() and (
        (path / "rgb.txt").is_file() or any((path / name).is_file() for name in ASSOCIATION_FILES)
    )


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def load_camera_json(path: Path) -> CameraIntrinsics:
    try:
        data = json.loads(path.read_text(), parse_constant=_no_constant)
    except FileNotFoundError as err:
        raise LogError(f"{path}: camera file not found; pass an existing camera.json") from err
    except (OSError, ValueError, RecursionError) as err:  # RecursionError: nested beyond any camera
        detail = "nested too deeply" if isinstance(err, RecursionError) else " ".join(str(err).split())[:120]
        raise LogError(f"{path}: not valid JSON ({detail}); expected "
                       '{"width", "height", "fx", "fy", "cx", "cy", "depth_scale"}') from err
    if not isinstance(data, dict):
        raise LogError(f"{path}: expected a JSON object with width, height, fx, fy, cx, cy")
    return CameraIntrinsics.from_dict(data, source=str(path))


def _read_list(path: Path) -> list[tuple[float, str]]:
    """``stamp path`` lines of rgb.txt / depth.txt."""
    try:
        text = path.read_text()
    except FileNotFoundError as err:
        raise LogError(f"{path}: file missing; a TUM folder needs rgb.txt and depth.txt "
                       "(or associations.txt)") from err
    except (OSError, UnicodeDecodeError) as err:
        raise LogError(f"{path}: cannot read ({err})") from err
    rows: list[tuple[float, str]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.split()
        try:
            stamp = float(parts[0])
        except ValueError as err:
            raise LogError(f"{path}:{number}: '{parts[0]}' is not a timestamp; "
                           "expected 'stamp path'") from err
        if len(parts) < 2 or not np.isfinite(stamp):
            raise LogError(f"{path}:{number}: expected 'stamp path', got '{line}'")
        rows.append((stamp, _inside(path, number, parts[1])))
    rows.sort(key=lambda r: r[0])
    return rows


def _inside(listing: Path, number: int, name: str) -> str:
    """An image path of a list file, which must name a file inside the log folder: an absolute
    path or one climbing out with ``..`` is refused (a log names its own images)."""
    import os.path

    normal = os.path.normpath(name)  # by text: a symlinked image folder stays allowed
    if os.path.isabs(normal) or normal == ".." or normal.startswith(".." + os.sep):
        raise LogError(f"{listing}:{number}: {name!r} lies outside the log folder; image paths must be "
                       "relative to it (e.g. rgb/0.000000.png)")
    return name


def _text(path: Path, what: str) -> str:
    """The text of a log's list file; a binary or unreadable file is a ``LogError``."""
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as err:
        raise LogError(f"{path}: not a text file (byte {err.start} is not UTF-8); expected {what}") from err
    except OSError as err:
        raise LogError(f"{path}: cannot read ({err.strerror or err})") from err


def _read_associations(path: Path) -> list[tuple[float, str, float, str]]:
    rows = []
    text = _text(path, "lines 't_rgb rgb_path t_depth depth_path'")
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.split()
        if len(parts) < 4:
            raise LogError(f"{path}:{number}: expected 't_rgb rgb_path t_depth depth_path', got '{line}'")
        try:
            rows.append((float(parts[0]), _inside(path, number, parts[1]), float(parts[2]),
                         _inside(path, number, parts[3])))
        except ValueError as err:
            raise LogError(f"{path}:{number}: not a timestamp ({err}); expected "
                           "'t_rgb rgb_path t_depth depth_path'") from err
    rows.sort(key=lambda r: r[0])
    return rows


def associate(a_s: NDArray[np.float64], b_s: NDArray[np.float64], max_dt_s: float) -> list[tuple[int, int]]:
    """Index pairs (i, j) with |a[i] - b[j]| <= max_dt_s, closest first, each index used once.

    ``a_s`` and ``b_s`` must be sorted. Returns the pairs sorted by ``i``.
    """
    if len(a_s) == 0 or len(b_s) == 0:
        return []
    candidates: list[tuple[float, int, int]] = []
    pos = np.searchsorted(b_s, a_s)
    for i, p in enumerate(pos):
        for j in range(max(p - 2, 0), min(p + 2, len(b_s))):
            dt = abs(float(a_s[i]) - float(b_s[j]))
            if dt <= max_dt_s:
                candidates.append((dt, i, j))
    candidates.sort()
    used_a: set[int] = set()
    used_b: set[int] = set()
    pairs = []
    for _, i, j in candidates:
        if i not in used_a and j not in used_b:
            used_a.add(i)
            used_b.add(j)
            pairs.append((i, j))
    return sorted(pairs)


def tum_camera(root: Path, camera: CameraIntrinsics | None = None) -> tuple[CameraIntrinsics, str]:
    """The intrinsics of a TUM folder and where they came from (see the module docstring)."""
    if camera is not None:
        return camera, "flags"
    if (root / "camera.json").is_file():
        return load_camera_json(root / "camera.json"), str(root / "camera.json")
    match = re.search(r"freiburg([123])", root.resolve().name)
    if match:
        key = f"fr{match.group(1)}"
        return TUM_PRESETS[key], f"preset {key}"
    raise LogError(f"{root}: missing camera intrinsics (no camera.json, folder name names no "
                   "freiburg1/2/3 preset); pass --camera camera.json, --preset fr1|fr2|fr3 "
                   "or --fx/--fy/--cx/--cy")


def _read_detections(path: Path) -> tuple[NDArray[np.float64], list[Detections]]:
    stamps: list[float] = []
    dets: list[Detections] = []
    text = _text(path, 'one JSON object per line, {"stamp_s": s, "detections": [...]}')
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
            stamps.append(float(record["stamp_s"]))
            dets.append(Detections.from_records(record.get("detections", [])))
        except (ValueError, KeyError, TypeError) as err:
            raise LogError(f"{path}:{number}: bad detections line ({err}); expected "
                           '{"stamp_s": s, "detections": [{"xyxy", "class", "score"}]}') from err
    order = np.argsort(stamps)
    return np.asarray(stamps, dtype=np.float64)[order], [dets[i] for i in order]


class TumReader(IndexedLog):
    """Reader of one TUM RGB-D folder (see the module docstring)."""

    def _read_images(self, entry: FrameEntry) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        rgb_path, depth_path = entry.locator
        return read_rgb_file(rgb_path), read_depth_png(depth_path, self.camera.depth_scale)


def _check_size(entry: FrameEntry, camera: CameraIntrinsics, camera_source: str) -> None:
    """Refuse intrinsics of another size than the first readable colour image, before iterating."""
    try:
        rgb = read_rgb_file(entry.locator[0])
    except LogError:
        return  # counted as a skipped frame while iterating
    height, width = rgb.shape[:2]
    if (width, height) != (camera.width, camera.height):
        raise LogError(f"{entry.locator[0]}: image is {width}×{height} but the camera intrinsics "
                       f"({camera_source}) are for {camera.width}×{camera.height}; pass the right "
                       "camera.json or camera flags")


def open_tum(root: Path, *, poses: Trajectory | None = None, camera: CameraIntrinsics | None = None,
             max_dt_s: float = 0.02) -> TumReader:
    """Index a TUM folder; ``poses`` replaces ``groundtruth.txt``, ``camera`` the folder's intrinsics."""
    cam, camera_source = tum_camera(root, camera)
    assoc = next((root / n for n in ASSOCIATION_FILES if (root / n).is_file()), None)
    if assoc is not None:
        rows = _read_associations(assoc)
        pairs = [(t_rgb, root / rgb, root / depth) for t_rgb, rgb, _, depth in rows]
        sources = {"rgb": str(assoc), "depth": str(assoc)}
    else:
        rgb_rows = _read_list(root / "rgb.txt")
        depth_rows = _read_list(root / "depth.txt")
        rgb_s = np.array([r[0] for r in rgb_rows])
        matched = associate(rgb_s, np.array([r[0] for r in depth_rows]), max_dt_s)
        pairs = [(rgb_rows[i][0], root / rgb_rows[i][1], root / depth_rows[j][1]) for i, j in matched]
        sources = {"rgb": str(root / "rgb.txt"), "depth": str(root / "depth.txt")}
        if rgb_rows and depth_rows and not pairs:
            raise LogError(f"{root}: no colour image has a depth image within {max_dt_s} s; "
                           "raise --max-dt or add associations.txt")
    if not pairs:
        raise LogError(f"{root}: the log lists no images; expected lines 'stamp path' in rgb.txt/depth.txt")
    sources["camera"] = camera_source

    if poses is not None:
        trajectory, pose_source = poses, f"trajectory {poses.source}"
    elif (root / "groundtruth.txt").is_file():
        trajectory = read_tum_trajectory(root / "groundtruth.txt")
        pose_source = f"groundtruth {root / 'groundtruth.txt'}"
    else:
        raise LogError(f"{root}: no poses (no groundtruth.txt); pass --poses traj.txt with your SLAM "
                       "trajectory in TUM format")
    sources["poses"] = trajectory.source

    stamps = np.array([p[0] for p in pairs], dtype=np.float64)
    T, valid = trajectory.interpolate(stamps, max_extrapolation_s=max_dt_s)

    det_stamps: NDArray[np.float64] | None = None
    det_list: list[Detections] = []
    if (root / "detections.jsonl").is_file():
        det_stamps, det_list = _read_detections(root / "detections.jsonl")
        sources["detections"] = str(root / "detections.jsonl")

    entries: list[FrameEntry] = []
    index_skipped: list[tuple[str, str]] = []
    for k, (stamp, rgb_path, depth_path) in enumerate(pairs):
        source = f"{rgb_path.relative_to(root)} + {depth_path.relative_to(root)}"
        if not valid[k]:
            index_skipped.append((source, f"stamp {stamp:.6f} outside the poses' time span "
                                          f"{trajectory.stamps_s[0]:.6f}..{trajectory.stamps_s[-1]:.6f}"))
            continue
        detections = None
        if det_stamps is not None:
            j = int(np.argmin(np.abs(det_stamps - stamp))) if len(det_stamps) else -1
            detections = (det_list[j] if j >= 0 and abs(det_stamps[j] - stamp) <= max_dt_s
                          else Detections.empty())
        entries.append(FrameEntry(float(stamp), T[k], source, (rgb_path, depth_path), detections))
    if not entries:
        raise LogError(f"{root}: no image stamp lies within the poses' time span "
                       f"{trajectory.stamps_s[0]:.6f}..{trajectory.stamps_s[-1]:.6f}; "
                       "check that --poses belongs to this log")
    _check_size(entries[0], cam, camera_source)
    return TumReader(
        path=str(root), format="tum", camera=cam, entries=entries, pose_source=pose_source,
        sources=sources, has_detections=det_stamps is not None, index_skipped=index_skipped,
    )
