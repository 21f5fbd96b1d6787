"""What ``hiper analyze heatmap`` writes: a PNG for people and nav2 costmap-filter masks.

nav2 masks are map_server maps in ``mode: raw`` (the pixel value is the OccupancyGrid value,
0-100; 101-255 read as unknown, -1), origin yaw 0, image row 0 at the top of the map, unknown
cells 255. Costmap filters turn a mask value into filter space as ``base + multiplier · value``
(``costmap_filter_info_server``); both masks here use base 0, multiplier 1:

- keepout (filter type 0): the heat in percent, 0-99 (cap 80 % gives at most 80): the keepout
  filter raises the cost of hot cells without making them lethal; 100 only at or above
  ``lethal_above`` when asked;
- speed limit (type 1, percent of the maximum speed): hot cells are slowed down to
  ``min_speed_percent`` at the peak; a cell that would allow 100 % is written 0, which nav2's
  speed filter reads as "no limit";
- inverse (type 0): the search map, low where the class is usually found.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.analyze.gridmap import FREE, OCCUPIED, UNKNOWN, write_map_server
from hiper_cli.analyze.heatmap import Heatmap
from hiper_cli.errors import ConfigError
from hiper_cli.files import output_folder

__all__ = ["MaskConfig", "keepout_mask", "render_png", "speed_mask", "write_outputs"]


@dataclass(frozen=True)
class MaskConfig:
    min_speed_percent: float = 30.0
    """Speed limit at the hottest cell, percent of the robot's maximum speed."""
    lethal_above: float | None = None
    """Heat (0-1) at or above which the keepout mask says 100 (a keepout zone); None: never."""
    filter_info_topic: str = "/costmap_filter_info"

    def __post_init__(self) -> None:
        if not 0.0 < self.min_speed_percent <= 100.0:
            raise ConfigError(f"min_speed_percent must be in (0, 100], got {self.min_speed_percent}")


def keepout_mask(
    heat: NDArray[np.float32], known: NDArray[np.bool_], lethal_above: float | None
) -> NDArray[np.uint8]:
    """Raw-mode keepout values (bottom-up): heat in percent, at most 99, 100 where asked, 255 unknown."""
    value = np.minimum(np.rint(heat * 100.0), 99.0)
    if lethal_above is not None:
        value[heat >= lethal_above] = 100.0
    return np.where(known, value, 255).astype(np.uint8)


def speed_mask(
    heat: NDArray[np.float32], known: NDArray[np.bool_], cap: float, min_percent: float
) -> NDArray[np.uint8]:
    """Raw-mode speed-limit values (bottom-up): percent of the maximum speed, 0 = no limit."""
    limit = np.rint(100.0 - (100.0 - min_percent) * np.clip(heat / cap, 0.0, 1.0))
    limit = np.where(limit >= 100.0, 0.0, np.clip(limit, 1.0, 100.0))
    return np.where(known, limit, 255).astype(np.uint8)


def render_png(hm: Heatmap, path: Path, *, inverse: bool = False, min_width_px: int = 800) -> Path:
    """The map in grey (walls dark, free light, unknown mid grey), the heat in colour over it,
    a colour bar legend in percent occupancy, class and window in the title."""
    import cv2

    cells = hm.grid.cells
    grey = np.full(cells.shape, 160, dtype=np.uint8)
    grey[cells == FREE] = 235
    grey[cells >= OCCUPIED * 0.65] = 40
    base = cv2.cvtColor(np.flipud(grey), cv2.COLOR_GRAY2BGR)
    value = hm.inverse if inverse else hm.heat
    cap = hm.config.occupancy_cap
    shown = np.flipud(np.clip(value / cap, 0.0, 1.0))
    colour = cv2.applyColorMap((shown * 255).astype(np.uint8), cv2.COLORMAP_INFERNO)
    alpha = np.where(np.flipud(cells) == UNKNOWN, 0.0, np.clip(shown * 1.5, 0.0, 0.85))[:, :, None]
    if not inverse:
        alpha = np.where(shown[:, :, None] < 0.02, 0.0, alpha)
    img = (base * (1 - alpha) + colour * alpha).astype(np.uint8)
    scale = max(1, int(np.ceil(min_width_px / img.shape[1])))
    img = cv2.resize(img, (img.shape[1] * scale, img.shape[0] * scale), interpolation=cv2.INTER_NEAREST)
    h, w = img.shape[:2]
    bar_w, pad, title_h = 28, 16, 44
    canvas = np.full((h + title_h + pad, w + bar_w + 5 * pad, 3), 255, dtype=np.uint8)
    canvas[title_h : title_h + h, pad : pad + w] = img
    ramp = np.linspace(1.0, 0.0, h)[:, None].repeat(bar_w, axis=1)
    bar = cv2.applyColorMap((ramp * 255).astype(np.uint8), cv2.COLORMAP_INFERNO)
    x0 = 2 * pad + w
    canvas[title_h : title_h + h, x0 : x0 + bar_w] = bar
    font = cv2.FONT_HERSHEY_SIMPLEX
    for frac in (0.0, 0.5, 1.0):
        y = int(title_h + (1.0 - frac) * (h - 1))
        cv2.putText(
            canvas,
            f"{100 * frac * cap:.0f}%",
            (x0 + bar_w + 4, min(max(y + 5, title_h + 10), title_h + h)),
            font,
            0.45,
            (0, 0, 0),
            1,
            cv2.LINE_AA,
        )
    what = "inverse heatmap (search)" if inverse else "heatmap"
    title = f"{hm.class_name} {what}, {hm.window.describe()}, {hm.rows} rows of {hm.instances} tracks"
    cv2.putText(canvas, title, (pad, 28), font, 0.6, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(
        canvas,
        f"occupancy, cap {100 * cap:.0f}%; 1 px = {hm.grid.resolution_m / scale:.3f} m",
        (pad, title_h + h + 12),
        font,
        0.4,
        (60, 60, 60),
        1,
        cv2.LINE_AA,
    )
    if not cv2.imwrite(str(path), canvas, [cv2.IMWRITE_PNG_COMPRESSION, 1]):
        raise ConfigError(f"{path}: cannot write the PNG; check the folder is writable")
    return path


def _filter_params(stem: str, kind: str, ftype: int, mask_yaml: str, config: MaskConfig) -> str:
    return (
        f"{stem}_filter_mask_server:\n"
        "  ros__parameters:\n"
        f"    topic_name: /{stem}_filter_mask\n"
        f"    yaml_filename: {mask_yaml}\n"
        f"{stem}_costmap_filter_info_server:\n"
        "  ros__parameters:\n"
        f"    type: {ftype}  # {kind}\n"
        f"    filter_info_topic: {config.filter_info_topic}_{stem}\n"
        f"    mask_topic: /{stem}_filter_mask\n"
        "    base: 0.0\n"
        "    multiplier: 1.0\n"
    )


def _snippet(stem_keepout: str, stem_speed: str, config: MaskConfig) -> str:
    return (
        "# merge into your nav2 params: global_costmap (and local_costmap) filters\n"
        "global_costmap:\n"
        "  global_costmap:\n"
        "    ros__parameters:\n"
        f'      filters: ["{stem_keepout}_filter", "{stem_speed}_filter"]\n'
        f"      {stem_keepout}_filter:\n"
        "        plugin: nav2_costmap_2d::KeepoutFilter\n"
        "        enabled: true\n"
        f"        filter_info_topic: {config.filter_info_topic}_{stem_keepout}\n"
        f"      {stem_speed}_filter:\n"
        "        plugin: nav2_costmap_2d::SpeedFilter\n"
        "        enabled: true\n"
        f"        filter_info_topic: {config.filter_info_topic}_{stem_speed}\n"
        "        speed_limit_topic: /speed_limit\n"
    )


def write_outputs(
    hm: Heatmap, out_dir: str | Path, config: MaskConfig | None = None, *, inverse: bool = False
) -> dict[str, str]:
    """Write the PNG(s), the keepout and speed masks (raw PGM + YAML), the inverse mask with
    ``inverse``, the filter servers' parameters and the costmap ``filters:`` snippet into
    ``out_dir``; returns name -> path."""
    config = config or MaskConfig()
    out = output_folder(out_dir)
    stem = f"heatmap_{hm.class_name.replace(' ', '_')}"
    known = hm.grid.cells != UNKNOWN
    files: dict[str, str] = {"png": str(render_png(hm, out / f"{stem}.png"))}
    keep_yaml, keep_pgm = write_map_server(
        hm.grid,
        out / f"{stem}_keepout.yaml",
        mode="raw",
        image=keepout_mask(hm.heat, known, config.lethal_above),
    )
    speed_yaml, speed_pgm = write_map_server(
        hm.grid,
        out / f"{stem}_speed.yaml",
        mode="raw",
        image=speed_mask(hm.heat, known, hm.config.occupancy_cap, config.min_speed_percent),
    )
    files |= {
        "keepout_yaml": str(keep_yaml),
        "keepout_pgm": str(keep_pgm),
        "speed_yaml": str(speed_yaml),
        "speed_pgm": str(speed_pgm),
    }
    params = _filter_params("keepout", "keepout zones / preferred lanes", 0, keep_yaml.name, config)
    params += _filter_params(
        "speed", "speed limit in % of maximum speed, 0 = no limit", 1, speed_yaml.name, config
    )
    if inverse:
        files["inverse_png"] = str(render_png(hm, out / f"{stem}_inverse.png", inverse=True))
        inv_yaml, inv_pgm = write_map_server(
            hm.grid, out / f"{stem}_inverse.yaml", mode="raw", image=keepout_mask(hm.inverse, known, None)
        )
        files |= {"inverse_yaml": str(inv_yaml), "inverse_pgm": str(inv_pgm)}
        params += _filter_params("search", "inverse heatmap for search", 0, inv_yaml.name, config)
    params_path = out / f"{stem}_filter_params.yaml"
    params_path.write_text(params)
    snippet_path = out / f"{stem}_costmap_snippet.yaml"
    snippet_path.write_text(_snippet("keepout", "speed", config))
    files |= {"filter_params": str(params_path), "costmap_snippet": str(snippet_path)}
    return files
