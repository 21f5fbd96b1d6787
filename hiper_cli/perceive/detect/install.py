"""The models folder as ``hiper models`` and the agent tools see it: list, fetch, add, as data.

Each function returns the plain dict that ``hiper models ... --json`` prints, so the command
line, Python users and any other front end get the same answer.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect.catalog import CATALOG, ModelEntry, catalog_rows, entry, models_dir
from hiper_cli.perceive.detect.fetch import Progress, add_model, fetch_model

__all__ = ["add_model_file", "fetch_named_model", "list_models"]


def list_models(directory: Path | None = None) -> dict[str, Any]:
    """The models folder and one row per known or added model (``catalog_rows``)."""
    return {"models_dir": str(models_dir(directory)), "models": catalog_rows(directory)}


def fetch_named_model(name: str, directory: Path | None = None, *, url: str | None = None,
                      allow_unverified: bool = False,
                      on_start: Callable[[str, int | None], None] | None = None,
                      progress: Progress | None = None, timeout_s: float = 30.0) -> dict[str, Any]:
    """Download the catalog's model ``name`` (or alias) into the models folder (``fetch_model``):
    where it is and how it came. ``on_start(model name, size in bytes or None)`` once the name
    is known, before the download."""
    model = entry(name)
    if on_start is not None:
        on_start(model.name, model.size_bytes)
    result = fetch_model(model, models_dir(directory), url=url, allow_unverified=allow_unverified,
                         progress=progress, timeout_s=timeout_s)
    return {"name": model.name, "path": str(result.path), "sha256": result.sha256,
            "verified": result.verified, "downloaded_bytes": result.downloaded_bytes,
            "resumed_from": result.resumed_from, "url": url or model.url}


def add_model_file(path: Path, name: str | None = None, labels: Path | None = None,
                   directory: Path | None = None) -> dict[str, Any]:
    """Copy the ONNX file ``path`` into the models folder as ``name`` (default its stem), after
    opening it as a detector (a layout hiper reads; a known name must have its known sha256);
    ``labels`` (class names, one a line) goes beside it."""
    from hiper_cli.perceive.detect.onnx_model import OnnxDetector

    wanted = name or path.stem
    known = {e.name: e for e in CATALOG}
    model = known.get(wanted) or ModelEntry(wanted, "auto", 640, "(added)", None)
    if not path.is_file():
        raise ConfigError(f"{path}: no such file; pass the path of an .onnx model")
    detector = OnnxDetector(
        path, layout=None if model.layout == "auto" else model.layout, input_px=model.input_px, labels=labels
    )
    result = add_model(model, path, models_dir(directory))
    if labels is not None:
        shutil.copyfile(labels, result.path.with_name("labels.txt"))
    return {"name": model.name, "path": str(result.path), "sha256": result.sha256,
            "verified": result.verified, "layout": detector.layout, "classes": len(detector.class_names)}
