"""Foreground recognition and 3D multi-object tracking (paper sections IV-E to IV-H).

``ForegroundStage`` is the pipeline stage (registered as ``foreground``); ``ForegroundConfig``
holds its options. Segmentation (Algorithm 3) is in ``segment``, the semantic assignment
(Algorithm 4) in ``match``, the tracker in ``tracking``.
"""

from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.stage import ForegroundStage

__all__ = ["ForegroundConfig", "ForegroundStage"]
