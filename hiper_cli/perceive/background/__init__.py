"""Background recognition (paper IV-C/D): planes → wall/floor/ceiling/table instances.

``BackgroundStage`` implements the ``Stage`` protocol; ``BackgroundConfig`` holds its options;
``reanchor`` recomputes background instances from their observations with new poses.
"""

from hiper_cli.perceive.background.config import METHODS, BackgroundConfig
from hiper_cli.perceive.background.reanchor import reanchor
from hiper_cli.perceive.background.stage import BackgroundStage, observe

__all__ = ["METHODS", "BackgroundConfig", "BackgroundStage", "observe", "reanchor"]
