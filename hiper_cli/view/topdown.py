"""A top-down picture of a ``ViewScene`` (OpenCV, no Rerun): for the README and for reports.

Drawn in the map's x-y plane, +y up: the occupancy map in greys, floor polygons filled,
heatmaps over them in the turbo colour map (faint cells left out), walls and other
background planes as their footprint in the class colour, the robot's path in grey with its
start and end, each moving foreground track as a polyline coloured by speed (thin grey across
times it was not seen) with its last box footprint and a label (class, short uuid, mean speed);
a static instance only as its fused box's footprint and a label without speed (the jitter of
its sightings is not a path); "unknown" clusters faint, a 1 m grid, a scale bar, a legend and
the time window in the title.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.clock import span_text
from hiper_cli.errors import ConfigError
from hiper_cli.view.scene import TrackItem, ViewScene
from hiper_cli.view.style import SPEED_RED_MPS, class_color, speed_colors

__all__ = ["TopDownConfig", "draw_topdown", "render_topdown"]

_WHITE = (255, 255, 255)
_GRID = (232, 232, 232)
_INK = (40, 40, 40)
_FAINT = (190, 190, 190)
UNKNOWN = "unknown"
# A track whose path spans more than this is labelled with its speed.
MOVED_M = 0.5


@dataclass(frozen=True)
class TopDownConfig:
    """``px_per_m``: scale; ``margin_m``: space around the scene; ``max_px``: the longer side's
    cap (the scale shrinks to fit)."""

    px_per_m: float = 80.0
    margin_m: float = 0.8
    max_px: int = 2000


class _Canvas:
    """Map metres to pixels (+y up) on a white BGR image."""

    def __init__(self, lo: NDArray[np.float64], hi: NDArray[np.float64], config: TopDownConfig) -> None:
        span = np.maximum(hi - lo, 1.0) + 2 * config.margin_m
        self.scale = min(config.px_per_m, config.max_px / float(span.max()))
        self.lo = lo - config.margin_m
        self.header_px = 40
        self.w = int(np.ceil(span[0] * self.scale))
        self.h = int(np.ceil(span[1] * self.scale))
        self.image = np.full((self.h + self.header_px, self.w, 3), _WHITE, dtype=np.uint8)

    def px(self, xy: NDArray[np.float64]) -> NDArray[np.int32]:
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        u = (xy[:, 0] - self.lo[0]) * self.scale
        v = self.header_px + self.h - (xy[:, 1] - self.lo[1]) * self.scale
        return np.round(np.stack([u, v], axis=1)).astype(np.int32)


def _bgr(rgb: tuple[int, ...] | NDArray[np.uint8]) -> tuple[int, int, int]:
    return int(rgb[2]), int(rgb[1]), int(rgb[0])


def _bounds(scene: ViewScene) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    pts = [b.box.corners()[:, :2] for b in scene.background]
    pts += [t.centers_map_m[:, :2] for t in scene.foreground]
    pts += [r.T_map_cam[:, :2, 3] for r in scene.robot]
    for f in scene.floor:
        x0, x1, y0, y1 = f.extent_m
        pts.append(np.array([[x0, y0], [x1, y1]]))
    if not pts:
        return np.zeros(2), np.ones(2)
    allpts = np.concatenate(pts)
    return allpts.min(axis=0), allpts.max(axis=0)


def _floor_images(canvas: _Canvas, scene: ViewScene, occupancy: bool) -> None:
    import cv2 as _cv2

    for image in (f for f in scene.floor if (f.kind == "occupancy") == occupancy):
        x0, x1, y0, y1 = image.extent_m
        (u0, v1), (u1, v0) = canvas.px(np.array([[x0, y0], [x1, y1]]))
        if u1 <= u0 or v1 <= v0:
            continue
        # Image rows run down, grid rows up (+y): flip, then BGR and alpha blending.
        rgba = _cv2.resize(np.flipud(image.rgba()), (u1 - u0, v1 - v0), interpolation=_cv2.INTER_NEAREST)
        ua, va = max(u0, 0), max(v0, 0)
        ub, vb = min(u1, canvas.image.shape[1]), min(v1, canvas.image.shape[0])
        region = canvas.image[va:vb, ua:ub]
        sub = rgba[va - v0 : vb - v0, ua - u0 : ub - u0]
        a = sub[:, :, 3:4].astype(np.float64) / 255.0
        region[:] = (region * (1 - a) + sub[:, :, 2::-1] * a).astype(np.uint8)


def _grid(canvas: _Canvas) -> None:
    import cv2 as _cv2

    hi = canvas.lo + np.array([canvas.w, canvas.h]) / canvas.scale
    for x in np.arange(np.ceil(canvas.lo[0]), hi[0]):
        u = int(canvas.px(np.array([[x, 0.0]]))[0, 0])
        _cv2.line(canvas.image, (u, canvas.header_px), (u, canvas.image.shape[0]), _GRID, 1)
    for y in np.arange(np.ceil(canvas.lo[1]), hi[1]):
        v = int(canvas.px(np.array([[0.0, y]]))[0, 1])
        _cv2.line(canvas.image, (0, v), (canvas.w, v), _GRID, 1)


def _footprint(box_corners: NDArray[np.float64]) -> NDArray[np.float64]:
    """The convex hull (K, 2) of a box's corners seen from above."""
    import cv2

    hull = cv2.convexHull(box_corners[:, :2].astype(np.float32))
    return np.asarray(hull, dtype=np.float64).reshape(-1, 2)


def _text(img: NDArray[np.uint8], text: str, at: tuple[int, int], color: tuple[int, int, int],
          scale: float = 0.45) -> None:
    import cv2

    # A white halo from shifted copies: a thicker stroke would widen the glyphs (OpenCV 5 fonts).
    for du, dv in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        cv2.putText(img, text, (at[0] + du, at[1] + dv), cv2.FONT_HERSHEY_SIMPLEX, scale, _WHITE, 1,
                    cv2.LINE_AA)
    cv2.putText(img, text, at, cv2.FONT_HERSHEY_SIMPLEX, scale, color, 1, cv2.LINE_AA)


def render_topdown(scene: ViewScene, config: TopDownConfig | None = None) -> NDArray[np.uint8]:
    """The picture as an (H, W, 3) uint8 BGR image."""
    import cv2

    config = config or TopDownConfig()
    canvas = _Canvas(*_bounds(scene), config)
    img = canvas.image
    _floor_images(canvas, scene, occupancy=True)
    _grid(canvas)
    floors = [b for b in scene.background if b.class_name == "floor"]
    for item in floors:
        poly = item.contour_map_m[:, :2] if len(item.contour_map_m) >= 3 else _footprint(item.box.corners())
        layer = img.copy()
        cv2.fillPoly(layer, [canvas.px(poly)], _bgr(class_color("floor")))
        img[:] = cv2.addWeighted(layer, 0.5, img, 0.5, 0)
    _floor_images(canvas, scene, occupancy=False)
    for item in scene.background:
        if item.class_name == "floor":
            continue
        thick = max(2, int(0.06 * canvas.scale))
        color = _bgr(class_color(item.class_name))
        cv2.polylines(img, [canvas.px(_footprint(item.box.corners()))], True, color, thick, cv2.LINE_AA)
    for robot in scene.robot:
        xy = canvas.px(robot.T_map_cam[:, :2, 3])
        cv2.polylines(img, [xy], False, (150, 150, 150), 2, cv2.LINE_AA)
        start, end = (int(xy[0][0]), int(xy[0][1])), (int(xy[-1][0]), int(xy[-1][1]))
        cv2.circle(img, start, 5, (150, 150, 150), -1, cv2.LINE_AA)
        cv2.circle(img, end, 6, _INK, 2, cv2.LINE_AA)
        _text(img, "robot", (end[0] + 8, end[1] + 14), _INK, 0.4)
    # Unrecognised clusters ("unknown") faint and unlabelled underneath, the recognised on top.
    tracks = sorted(scene.foreground, key=lambda t: t.class_name != UNKNOWN)
    gap_s = scene.gap_s()
    for track in tracks:
        faint = track.class_name == UNKNOWN
        if track.is_static:
            _static(img, canvas, track, faint)
            continue
        xy = canvas.px(track.centers_map_m[:, :2])
        if faint:
            cv2.polylines(img, [xy], False, _FAINT, 1, cv2.LINE_AA)
        else:
            seg = speed_colors((track.speed_mps[:-1] + track.speed_mps[1:]) / 2.0)
            seen = track.seen_segments(gap_s)
            for k, c in enumerate(seg):
                a, b = (int(xy[k][0]), int(xy[k][1])), (int(xy[k + 1][0]), int(xy[k + 1][1]))
                cv2.line(img, a, b, _bgr(c) if seen[k] else _FAINT, 3 if seen[k] else 1, cv2.LINE_AA)
        last = track.box.corners() - track.box.center_m + track.centers_map_m[-1]
        color = _FAINT if faint else _bgr(class_color(track.class_name))
        cv2.polylines(img, [canvas.px(_footprint(last))], True, color, 1 if faint else 2, cv2.LINE_AA)
        if not faint:
            u, v = (int(a) for a in xy[-1])
            moved = track.state == "dynamic" or track.span_m > MOVED_M
            speed = f" {track.mean_speed_mps:.2f} m/s" if moved else ""
            _text(img, f"{track.class_name} {track.uuid[-4:]}{speed}", (u + 8, v - 8), color)
    _header(img, scene, canvas)
    return img


def _static(img: NDArray[np.uint8], canvas: _Canvas, track: TrackItem, faint: bool) -> None:
    """A static instance: its fused box's footprint and its label; no path, no speed."""
    import cv2

    color = _FAINT if faint else _bgr(class_color(track.class_name))
    footprint = canvas.px(_footprint(track.box.corners()))
    cv2.polylines(img, [footprint], True, color, 1 if faint else 2, cv2.LINE_AA)
    if not faint:
        u, v = (int(a) for a in canvas.px(track.box.center_m[:2])[0])
        _text(img, f"{track.class_name} {track.uuid[-4:]}", (u + 8, v - 8), color)


def _header(img: NDArray[np.uint8], scene: ViewScene, canvas: _Canvas) -> None:
    import cv2

    title = (f"{Path(scene.kb_path).name}: {len(scene.background)} background, {len(scene.foreground)} "
             f"foreground, {span_text(scene.t_min_s, scene.t_max_s)}")
    _text(img, title, (8, 16), _INK, 0.5)
    classes = sorted({b.class_name for b in scene.background} | {t.class_name for t in scene.foreground})
    u = 8
    for cls in classes:
        cv2.rectangle(img, (u, 24), (u + 10, 34), _bgr(class_color(cls)), -1)
        _text(img, cls, (u + 14, 34), _INK, 0.4)
        u += 24 + 8 * len(cls)
    # Speed ramp and a 1 m scale bar, at the right of the header.
    right = canvas.w - 8
    bar = int(canvas.scale)
    cv2.line(img, (right - bar, 30), (right, 30), _INK, 3)
    _text(img, "1 m", (right - bar, 22), _INK, 0.4)
    ramp = speed_colors(np.linspace(0, SPEED_RED_MPS, 60))
    x0 = right - bar - 150
    for k, c in enumerate(ramp):
        cv2.line(img, (x0 + k, 24), (x0 + k, 34), _bgr(c), 1)
    _text(img, f"0-{SPEED_RED_MPS:g} m/s", (x0 + 64, 34), _INK, 0.4)


def draw_topdown(scene: ViewScene, out: Path, config: TopDownConfig | None = None) -> tuple[int, int]:
    """Write the picture to ``out`` (PNG); its (width, height) in pixels."""
    import cv2

    img = render_topdown(scene, config)
    if out.suffix.lower() != ".png":
        raise ConfigError(f"{out}: the picture is written as PNG; name it {out.with_suffix('.png').name}")
    out.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(out), img):
        raise ConfigError(f"{out}: cannot write the picture there; check the folder is writable")
    return img.shape[1], img.shape[0]
