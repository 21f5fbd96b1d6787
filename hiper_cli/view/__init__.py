"""See the scene memory: a Rerun recording on the log's timeline and a top-down picture.

One public entry, ``render_view(ViewRequest(...))``; ``load_scene`` reads a knowledge base
into the typed ``ViewScene`` that ``write_scene`` (Rerun, the ``view`` extra) and
``draw_topdown`` (OpenCV) draw. Sits after ``graph`` in the import order. docs/view.md.
"""

from hiper_cli.view.api import ViewRequest, ViewSummary, render_view
from hiper_cli.view.floor import FloorImage
from hiper_cli.view.scene import BackgroundItem, RobotPath, TimeWindow, TrackItem, ViewScene, load_scene
from hiper_cli.view.topdown import draw_topdown, render_topdown

__all__ = [
    "BackgroundItem",
    "FloorImage",
    "RobotPath",
    "TimeWindow",
    "TrackItem",
    "ViewRequest",
    "ViewScene",
    "ViewSummary",
    "draw_topdown",
    "load_scene",
    "render_topdown",
    "render_view",
]
