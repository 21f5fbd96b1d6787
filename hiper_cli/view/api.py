"""``render_view``: the one entry of ``hiper view``: a knowledge base (and optionally its log)
to a Rerun recording, a live viewer and/or a top-down PNG."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.clock import span_text
from hiper_cli.errors import ConfigError
from hiper_cli.view.scene import TimeWindow, ViewScene, load_scene

__all__ = ["ViewRequest", "ViewSummary", "render_view"]


@dataclass(frozen=True)
class ViewRequest:
    """What to draw and where. ``rrd``: recording file; ``spawn``: stream to a new viewer;
    ``png``: top-down picture; at least one of them. ``log``: the sensor log, for the camera's
    images and intrinsics; ``image_hz``: frames per second of it to log (0: all)."""

    kb: str
    rrd: Path | None = None
    spawn: bool = False
    png: Path | None = None
    log: Path | None = None
    window: TimeWindow = field(default_factory=TimeWindow)
    image_hz: float = 2.0

    def __post_init__(self) -> None:
        if self.rrd is None and not self.spawn and self.png is None:
            raise ConfigError("nothing to write: pass -o scene.rrd, --spawn or --png OUT.png")
        if self.rrd is not None and self.rrd.suffix != ".rrd":
            raise ConfigError(f"-o {self.rrd}: a Rerun recording ends in .rrd; name it "
                              f"{self.rrd.with_suffix('.rrd').name}")
        if self.image_hz < 0:
            raise ConfigError(f"--image-hz {self.image_hz:g}: expected 0 (every frame) or a positive rate")


@dataclass(frozen=True)
class ViewSummary:
    kb: str
    rrd: str | None
    png: str | None
    png_size_px: tuple[int, int] | None
    t_min_s: float
    t_max_s: float
    counts: dict[str, int]
    frames_logged: int
    rrd_bytes: int | None
    seconds: float

    def line(self) -> str:
        """One line for people: what was written and what it holds."""
        wrote = ", ".join(p for p in (self.rrd, self.png) if p) or "the viewer"
        return (f"{wrote}: {self.counts['background']} background, {self.counts['foreground']} foreground "
                f"instances, {self.frames_logged} frames, {span_text(self.t_min_s, self.t_max_s, 'g')}")

    def to_dict(self) -> dict[str, Any]:
        return {"kb": self.kb, "rrd": self.rrd, "png": self.png,
                "png_size_px": list(self.png_size_px) if self.png_size_px else None,
                "t_min_s": self.t_min_s, "t_max_s": self.t_max_s, "counts": self.counts,
                "frames_logged": self.frames_logged, "rrd_bytes": self.rrd_bytes, "seconds": self.seconds}


def _record(request: ViewRequest, scene: ViewScene, kb: Any) -> tuple[dict[str, int], int]:
    from hiper_cli.view.recording import Timeline, import_rerun, new_recording, write_scene

    import_rerun()  # says how to install before the log is opened
    reader = camera = None
    if request.log is not None:
        from hiper_cli.perceive.logs import open_log

        reader = open_log(request.log)
        camera = reader.info().camera
    rec = new_recording(request.rrd, request.spawn, with_images=reader is not None)
    counts = write_scene(rec, scene, camera)
    frames = 0
    if reader is not None:
        from hiper_cli.view.camera import log_frames

        timeline = Timeline(import_rerun(), rec, scene)
        frames = log_frames(rec, timeline.set, reader, kb, request.window, request.image_hz)
    rec.flush()
    rec.disconnect()
    return counts, frames


def render_view(request: ViewRequest) -> ViewSummary:
    """Read the scene of ``request.kb`` and write what the request asks for."""
    from hiper_cli.graph import open_kb_for_reading

    started = time.perf_counter()
    counts: dict[str, int] = {}
    frames = 0
    size = None
    with open_kb_for_reading(request.kb) as kb:
        scene = load_scene(kb, request.window, request.log)
        if request.rrd is not None or request.spawn:
            counts, frames = _record(request, scene, kb)
    if request.png is not None:
        from hiper_cli.view.topdown import draw_topdown

        size = draw_topdown(scene, request.png)
    counts = counts or {"background": len(scene.background), "foreground": len(scene.foreground),
                        "poses": sum(len(r.stamps_s) for r in scene.robot), "floor_images": len(scene.floor)}
    return ViewSummary(kb=scene.kb_path, rrd=str(request.rrd) if request.rrd else None,
                       png=str(request.png) if request.png else None, png_size_px=size,
                       t_min_s=scene.t_min_s, t_max_s=scene.t_max_s, counts=counts, frames_logged=frames,
                       rrd_bytes=request.rrd.stat().st_size if request.rrd and request.rrd.exists() else None,
                       seconds=round(time.perf_counter() - started, 3))
