"""The one interface every recognition stage implements, and the registry of stages.

The perception pipeline (``hiper_cli.pipeline``) owns the ``World`` (defined, like
``FrameResult``, in ``hiper_cli.model`` and re-exported here): the current instances per layer
and the learned priors (analyses). For every frame it calls each stage's
``process`` in order (background before foreground, so the foreground sees the background
of this frame), applies the returned ``FrameResult`` to the world and writes it to the
knowledge base in one atomic transaction. Stages never touch the knowledge base themselves,
which keeps ``perceive`` free of storage imports.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from typing import Any, Protocol, runtime_checkable

from hiper_cli.errors import ConfigError
from hiper_cli.model import FrameResult, World
from hiper_cli.types import Frame

__all__ = ["STAGES", "FrameResult", "Stage", "World", "make_stage"]


@runtime_checkable
class Stage(Protocol):
    """A recognition stage. ``name`` is its registry name."""

    name: str

    def process(self, frame: Frame, world: World) -> FrameResult:
        """Recognise what ``frame`` shows, given the current ``world``."""
        ...

    def finish(self, world: World) -> FrameResult:
        """Flush state at the end of a log (e.g. close tracks)."""
        ...


# name -> "module:factory"; a factory takes keyword options and returns a Stage.
STAGES: dict[str, str] = {
    "background": "hiper_cli.perceive.background:BackgroundStage",
    "foreground": "hiper_cli.perceive.foreground:ForegroundStage",
}


def make_stage(name: str, **options: Any) -> Stage:
    """Build the stage registered as ``name`` with ``options``."""
    if name not in STAGES:
        raise ConfigError(f"unknown stage {name!r}; expected one of {', '.join(sorted(STAGES))}")
    module_name, factory_name = STAGES[name].split(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as err:
        if err.name and module_name.startswith(err.name):
            raise ConfigError(f"stage {name!r} is not available in this version of hiper") from err
        raise
    stage: Stage = getattr(module, factory_name)(**options)
    return stage


def stage_names(names: Sequence[str]) -> list[str]:
    """Validate a list of stage names, keeping registry order (background first)."""
    unknown = [n for n in names if n not in STAGES]
    if unknown:
        raise ConfigError(f"unknown stage(s) {unknown}; expected one of {', '.join(STAGES)}")
    return [n for n in STAGES if n in names]
