"""``hiper analyze heatmap`` as one library call: query the class's rows and μ_v, draw them on
the environment's map, write the files and record the heatmap as an analysis."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.analyze.costmap import MaskConfig, write_outputs
from hiper_cli.analyze.features import FeatureConfig, check_classes, object_dynamics
from hiper_cli.analyze.heatmap import Heatmap, HeatmapConfig, heatmap_from_rows
from hiper_cli.analyze.maplayer import MapConfig, environment_of, map_for
from hiper_cli.analyze.window import TimeWindow
from hiper_cli.errors import DataError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.learned import KIND_HEATMAP, KIND_ODS, ObjectDynamics
from hiper_cli.model import Analysis

__all__ = ["HeatmapResult", "generate_heatmap", "learned_speed_mps"]


@dataclass(frozen=True)
class HeatmapResult:
    heatmap: Heatmap
    files: dict[str, str]
    speed_source: str

    def to_dict(self) -> dict[str, Any]:
        return self.heatmap.summary() | {"speed_source": self.speed_source, "files": self.files}


def learned_speed_mps(kb: KnowledgeBase, class_name: str) -> float | None:
    """μ_v of the newest ``ods`` analysis of ``class_name``, if there is one with motion."""
    found = kb.analyses(KIND_ODS, class_name)
    if not found:
        return None
    newest = max(found, key=lambda a: float(a.created_s))
    return ObjectDynamics.from_values(newest.values).mean_mps


def _nothing_in(kb: KnowledgeBase, class_name: str, window: TimeWindow) -> str:
    """Why a window holds no row of a class, and when the class was seen."""
    every = kb.trajectory_columns(class_name).rows[:, 0]
    seen = f"from {every.min():.1f} to {every.max():.1f} s" if every.size else "in no trajectory row"
    return (f"no {class_name} trajectory rows in the window ({window.describe()}); {kb.location} holds "
            f"them {seen}: widen --from/--to, --last or --daily")


def generate_heatmap(
    kb: KnowledgeBase,
    class_name: str,
    window: TimeWindow | None = None,
    out_dir: str | Path = ".",
    *,
    env_name: str | None = None,
    map_yaml: str | None = None,
    inverse: bool = False,
    config: HeatmapConfig | None = None,
    map_config: MapConfig | None = None,
    mask_config: MaskConfig | None = None,
    store: bool = True,
) -> HeatmapResult:
    """The heatmap of ``class_name`` in ``window`` on the environment's map, its files in
    ``out_dir`` and (``store``) a ``heatmap`` analysis listing them; ``store=False`` writes
    nothing to the knowledge base (nor the map it builds)."""
    window = window or TimeWindow()
    check_classes(kb, [class_name])
    env = environment_of(kb, env_name)
    tracks = kb.trajectory_columns(class_name, window.t_start_s, window.t_end_s)
    keep = window.mask(tracks.rows[:, 0])
    if not np.any(keep):  # before the map is built and stored: bad input changes nothing
        raise DataError(_nothing_in(kb, class_name, window))
    grid = map_for(kb, env, map_yaml, map_config, store=store)
    speed = learned_speed_mps(kb, class_name)
    source = "ods analysis"
    if speed is None:
        rows, track = tracks.rows[keep], tracks.track[keep]
        speeds = np.hypot(rows[:, 4], rows[:, 5])
        still = tracks.instances.static[track]
        ods = object_dynamics(speeds, track, FeatureConfig(bootstrap_samples=10), still)
        speed, source = (0.0 if ods.mean_mps is None else ods.mean_mps), "these rows"
    hm = heatmap_from_rows(class_name, tracks.rows, tracks.track, grid, window, speed, config)
    files = write_outputs(hm, out_dir, mask_config, inverse=inverse)
    if store:
        lo = window.t_start_s if window.t_start_s is not None else float(tracks.rows[:, 0].min(initial=0.0))
        hi = window.t_end_s if window.t_end_s is not None else float(tracks.rows[:, 0].max(initial=0.0))
        values = hm.summary() | {"files": files, "speed_source": source}
        kb.put_analyses([Analysis(KIND_HEATMAP, class_name, lo, hi, values, time.time())], env_uuid=env.uuid)
    return HeatmapResult(hm, files, source)
