"""Interpretation of the knowledge base (paper VI): learned features (ODS, size, altitude), the
map layer (occupancy grids) and heatmaps with nav2 costmap-filter masks.

Public entries: ``learn_features`` (``hiper analyze features``), ``generate_heatmap``
(``hiper analyze heatmap``), ``export_map`` (``hiper analyze map``); the typed features they
store are in ``hiper_cli.learned`` (perception reads them back).
"""

from hiper_cli.analyze.costmap import MaskConfig
from hiper_cli.analyze.features import (
    ClassFeatures,
    FeatureConfig,
    FeatureReport,
    compute_features,
    learn_features,
)
from hiper_cli.analyze.generate import HeatmapResult, generate_heatmap
from hiper_cli.analyze.gridmap import OccupancyGrid, read_map_server, write_map_server
from hiper_cli.analyze.heatmap import Heatmap, HeatmapConfig, heatmap_from_rows
from hiper_cli.analyze.maplayer import MapConfig, build_map, export_map
from hiper_cli.analyze.window import TimeWindow, resolve_window
from hiper_cli.learned import AltitudeFeature, ObjectDynamics, SizeFeature

__all__ = [
    "AltitudeFeature",
    "ClassFeatures",
    "FeatureConfig",
    "FeatureReport",
    "Heatmap",
    "HeatmapConfig",
    "HeatmapResult",
    "MapConfig",
    "MaskConfig",
    "ObjectDynamics",
    "OccupancyGrid",
    "SizeFeature",
    "TimeWindow",
    "build_map",
    "compute_features",
    "export_map",
    "generate_heatmap",
    "heatmap_from_rows",
    "learn_features",
    "read_map_server",
    "resolve_window",
    "write_map_server",
]
