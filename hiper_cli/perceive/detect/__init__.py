"""2D object detectors behind one interface, chosen by name.

``make_detector(name, log_path=...)`` builds one of:

- ``yolox``: the COCO YOLOX-Nano ONNX model (see ``hiper_cli.perceive.detect.yolox``);
- a model of the catalog (``yolox_s``, ``yolo11n``, ``rtdetr-l``, ...) or one added with
  ``hiper models add``, found in the models folders (``catalog``);
- ``onnx:PATH``: a user's ONNX export in any layout of ``layouts`` (YOLOX, YOLOv5, YOLOv8 /
  YOLO11, RT-DETR / RF-DETR);
- ``log``: the detections recorded in the log (``Frame.detections``);
- ``truth``: the simulator's noisy ground-truth detections (``LOG/gt/detections.jsonl``).

Every detector turns its native output into ``Detections`` (pixel xyxy boxes, class names,
scores) so that no later stage sees an ONNX tensor.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from hiper_cli.errors import ConfigError
from hiper_cli.types import Detections, Frame

__all__ = ["DETECTOR_NAMES", "Detector", "check_class_names", "make_detector"]


@runtime_checkable
class Detector(Protocol):
    """Finds objects in the colour image of a frame."""

    name: str

    def detect(self, frame: Frame) -> Detections:
        """The 2D detections of ``frame.rgb`` in pixel coordinates of that image."""
        ...


DETECTOR_NAMES: tuple[str, ...] = ("yolox", "onnx:PATH", "log", "truth")


def make_detector(name: str, *, log_path: str | Path | None = None, **options: Any) -> Detector:
    """Build the detector registered as ``name``; unknown names raise ``ConfigError``.

    ``log_path`` is the log being processed (the ``truth`` detector reads its ``gt/`` folder);
    ``options`` go to the detector's constructor (e.g. ``score_threshold``).
    """
    if name == "yolox":
        from hiper_cli.perceive.detect.yolox import YoloxDetector

        return YoloxDetector(**options)
    if name.startswith("onnx:"):
        from hiper_cli.perceive.detect.onnx_model import OnnxDetector

        path = name[len("onnx:") :]
        if not path:
            raise ConfigError("detector 'onnx:PATH' needs a path, e.g. onnx:models/yolo11n.onnx")
        return OnnxDetector(Path(path), **options)
    if name == "log":
        from hiper_cli.perceive.detect.recorded import LogDetector

        return LogDetector(**options)
    if name == "truth":
        from hiper_cli.perceive.detect.recorded import TruthDetector

        if log_path is None:
            raise ConfigError(
                "detector 'truth' needs the log folder (log_path=...) to read gt/detections.jsonl; "
                "it only works on logs written by hiper sim"
            )
        return TruthDetector(Path(log_path), **options)
    return _catalog_detector(name, options)


def _catalog_detector(name: str, options: dict[str, Any]) -> Detector:
    """A model of the catalog, or one added under ``name``, from the models folders."""
    from hiper_cli.perceive.detect.catalog import CATALOG, find_model, locate
    from hiper_cli.perceive.detect.onnx_model import OnnxDetector

    known = {e.name: e for e in CATALOG}
    if name in known:
        entry = known[name]
        return OnnxDetector(find_model(name), name=name, layout=entry.layout, input_px=entry.input_px,
                            **options)
    path = locate(name)
    if path is not None:
        return OnnxDetector(path, name=name, **options)
    raise ConfigError(
        f"unknown detector {name!r}; expected one of {', '.join(DETECTOR_NAMES)}, or a model of "
        f"'hiper models list' ({', '.join(known)})"
    )


def check_class_names(wanted: tuple[str, ...], excluded: tuple[str, ...], detector: Any, name: str) -> None:
    """Refuse ``--classes`` the detector can never report and ``--exclude-classes`` that name no
    class any detector reports: a typo would silently keep nothing, or exclude nothing."""
    known = getattr(detector, "class_names", None)
    _check_classes(wanted, known, name)
    _check_excluded(excluded, known or ())


def _check_excluded(excluded: tuple[str, ...], detector_classes: Any) -> None:
    """Refuse ``--exclude-classes`` that name no class any detector reports (a typo)."""
    from hiper_cli.perceive.detect._onnx import COCO_NAMES

    known = {*COCO_NAMES, *detector_classes}
    unknown = [c for c in excluded if c not in known]
    if unknown:
        import difflib

        near = difflib.get_close_matches(unknown[0], sorted(known), n=1)
        hint = f"did you mean {near[0]!r}? " if near else ""
        raise ConfigError(f"--exclude-classes {', '.join(unknown)}: no detector has such a class; {hint}"
                          "expected COCO class names such as 'boat,traffic light'")


def _check_classes(wanted: tuple[str, ...], known: Any, detector: str) -> None:
    """Refuse ``--classes`` the detector can never report (a typo would silently keep nothing)."""
    if not wanted or not known:
        return
    unknown = [c for c in wanted if c not in known]
    if unknown:
        import difflib

        near = difflib.get_close_matches(unknown[0], list(known), n=1)
        hint = f"did you mean {near[0]!r}? " if near else ""
        raise ConfigError(f"--classes {', '.join(unknown)}: detector {detector!r} has no such class; {hint}"
                          f"its classes: {', '.join(known)}")
