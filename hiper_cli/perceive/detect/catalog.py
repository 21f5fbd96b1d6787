"""The detector models hiper knows by name, and where their files are on this machine.

A ``ModelEntry`` says where a model is published (an official HTTPS release URL, or none when
its authors publish only weights to export), its sha256 when it has been verified, its
licence, its COCO val2017 mAP as published, and the output layout hiper reads. A sha256 is
only claimed for a file that was hashed; others are ``None`` ("unknown") and fetching them
needs ``allow_unverified`` (``hiper models fetch --trust-unverified``).

A model ``NAME`` lives at ``DIR/NAME/NAME.onnx``. ``models_dir()`` is where fetched models go:
``$HIPER_MODELS``, else the user cache (``$XDG_CACHE_HOME/hiper/models`` or
``~/.cache/hiper/models``). ``locate(NAME)`` searches that, then ``shared/models`` and
``models`` above the repository and the working directory.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError

__all__ = [
    "CATALOG",
    "ModelEntry",
    "catalog_rows",
    "entry",
    "find_model",
    "locate",
    "model_path",
    "models_dir",
    "search_dirs",
]

_YOLOX_RELEASE = "https://github.com/Megvii-BaseDetection/YOLOX/releases/download/0.1.1rc0"


@dataclass(frozen=True)
class ModelEntry:
    """A detector hiper knows: ``layout`` is one of ``layouts.LAYOUT_NAMES``; ``input_px`` the
    square input side; ``url`` None when no ONNX file is published (``export`` says how to make
    one); ``sha256``/``size_bytes`` None when not verified; ``coco_map`` the published COCO
    val2017 mAP 0.5:0.95 in percent, None when unknown."""

    name: str
    layout: str
    input_px: int
    licence: str
    coco_map: float | None
    url: str | None = None
    sha256: str | None = None
    size_bytes: int | None = None
    export: str | None = None

    @property
    def file_name(self) -> str:
        return f"{self.name}.onnx"


def _yolox(
    size: str, input_px: int, coco_map: float, sha256: str | None = None, size_bytes: int | None = None
) -> ModelEntry:
    return ModelEntry(
        f"yolox_{size}",
        "yolox",
        input_px,
        "Apache-2.0",
        coco_map,
        url=f"{_YOLOX_RELEASE}/yolox_{size}.onnx",
        sha256=sha256,
        size_bytes=size_bytes,
    )


# mAP: the publishers' model-zoo tables (YOLOX README; Ultralytics docs; RT-DETR paper).
CATALOG: tuple[ModelEntry, ...] = (
    _yolox("nano", 416, 25.8, "695e750a5d5754bb5a8d5325643b59282191a7e7a564e435a415fd3c578eab14", 3660092),
    _yolox("tiny", 416, 32.8),
    _yolox("s", 640, 40.5),
    _yolox("m", 640, 46.9),
    _yolox("l", 640, 49.7),
    _yolox("x", 640, 51.1),
    ModelEntry(
        "yolov5n",
        "yolov5",
        640,
        "AGPL-3.0",
        28.0,
        export="git clone ultralytics/yolov5 && python export.py --weights yolov5n.pt --include onnx",
    ),
    ModelEntry(
        "yolov8n",
        "yolov8",
        640,
        "AGPL-3.0",
        37.3,
        export="pip install ultralytics && yolo export model=yolov8n.pt format=onnx",
    ),
    ModelEntry(
        "yolo11n",
        "yolov8",
        640,
        "AGPL-3.0",
        39.5,
        export="pip install ultralytics && yolo export model=yolo11n.pt format=onnx",
    ),
    ModelEntry(
        "rtdetr-l",
        "detr",
        640,
        "AGPL-3.0",
        53.0,
        export="pip install ultralytics && yolo export model=rtdetr-l.pt format=onnx",
    ),
    ModelEntry(
        "rfdetr-base",
        "detr",
        560,
        "Apache-2.0",
        None,
        export="pip install rfdetr && python -c 'from rfdetr import RFDETRBase; RFDETRBase().export()'",
    ),
)
# "yolox" is the default detector: YOLOX-Nano.
_ALIASES = {"yolox": "yolox_nano"}


def entry(name: str) -> ModelEntry:
    """The catalog entry called ``name`` (or an alias such as ``yolox``); ``ConfigError`` naming
    the known ones otherwise."""
    wanted = _ALIASES.get(name, name)
    for e in CATALOG:
        if e.name == wanted:
            return e
    known = ", ".join(e.name for e in CATALOG)
    raise ConfigError(f"unknown model {name!r}; expected one of {known} (see 'hiper models list')")


def _user_cache() -> Path:
    cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(cache).expanduser() / "hiper" / "models"


def models_dir(override: str | Path | None = None) -> Path:
    """Where fetched and added models are written: ``override``, ``$HIPER_MODELS``, the user cache."""
    if override is not None:
        return Path(override).expanduser()
    env = os.environ.get("HIPER_MODELS")
    return Path(env).expanduser() if env else _user_cache()


def search_dirs(override: str | Path | None = None, roots: Sequence[Path] | None = None) -> list[Path]:
    """Folders searched for models, first match wins: ``models_dir(override)``, the user cache,
    then ``shared/models`` and ``models`` in ``roots`` (default: the repository and the working
    directory) and in their parents."""
    dirs = [models_dir(override), _user_cache()]
    if roots is None:
        roots = (Path(__file__).resolve().parents[3], Path.cwd().resolve())
    for base in roots:
        for parent in (base, *base.parents):
            dirs += [parent / "shared" / "models", parent / "models"]
    return list(dict.fromkeys(dirs))


def model_path(directory: Path, name: str) -> Path:
    """Where model ``name`` lives inside a models folder."""
    return directory / name / f"{name}.onnx"


def locate(name: str, override: str | Path | None = None, roots: Sequence[Path] | None = None) -> Path | None:
    """The model file called ``name`` (a catalog name or one added with ``hiper models add``)
    in the first folder of ``search_dirs`` that has it; None when none has."""
    wanted = _ALIASES.get(name, name)
    for d in search_dirs(override, roots):
        path = model_path(d, wanted)
        if path.is_file():
            return path
    return None


def find_model(name: str, override: str | Path | None = None, roots: Sequence[Path] | None = None) -> Path:
    """Like ``locate`` but a missing model is a ``ConfigError`` that says how to get it."""
    path = locate(name, override, roots)
    if path is not None:
        return path
    wanted = _ALIASES.get(name, name)
    known = next((e for e in CATALOG if e.name == wanted), None)
    where = models_dir(override)
    if known is not None and known.url is not None:
        flag = "" if known.sha256 else " --trust-unverified"
        fix = f"run 'hiper models fetch {wanted}{flag}' (or download {known.url}, 'hiper models add FILE')"
    elif known is not None:
        fix = f"export it ({known.export}) and run 'hiper models add {wanted}.onnx'"
    else:
        fix = f"add it with 'hiper models add FILE --name {wanted}', or pass --detector onnx:PATH"
    raise ConfigError(f"detector model {wanted!r} not found in {where} nor shared/models; {fix}")


def _row(e: ModelEntry, path: Path | None) -> dict[str, Any]:
    return {
        "name": e.name,
        "layout": e.layout,
        "input_px": e.input_px,
        "licence": e.licence,
        "coco_map": e.coco_map,
        "size_bytes": e.size_bytes,
        "sha256": e.sha256,
        "url": e.url,
        "export": e.export,
        "path": str(path) if path is not None else None,
    }


def catalog_rows(
    override: str | Path | None = None, roots: Sequence[Path] | None = None
) -> list[dict[str, Any]]:
    """One row per known model (and per model added under another name): what it is, and
    where it is on this machine (``path`` None when not found)."""
    rows = [_row(e, locate(e.name, override, roots)) for e in CATALOG]
    known = {e.name for e in CATALOG}
    folder = models_dir(override)
    added = (
        sorted(p.parent.name for p in folder.glob("*/*.onnx") if p.stem == p.parent.name)
        if folder.is_dir()
        else []
    )
    for name in added:
        if name not in known:
            path = model_path(folder, name)
            rows.append(
                {
                    "name": name,
                    "layout": "auto",
                    "input_px": None,
                    "licence": "(added by you)",
                    "coco_map": None,
                    "size_bytes": path.stat().st_size,
                    "sha256": None,
                    "url": None,
                    "export": None,
                    "path": str(path),
                }
            )
    return rows
