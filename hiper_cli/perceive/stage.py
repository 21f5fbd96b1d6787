"""The one interface every recognition stage implements, and the registry of stages.

The perception pipeline (``hiper_cli.pipeline``) owns the ``World``: the current instances
per layer and the learned priors (analyses). For every frame it calls each stage's
``process`` in order (background before foreground, so the foreground sees the background
of this frame), applies the returned ``FrameResult`` to the world and writes it to the
knowledge base in one atomic transaction. Stages never touch the knowledge base themselves,
which keeps ``perceive`` free of storage imports.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

from hiper_cli.errors import ConfigError
from hiper_cli.model import Analysis, Instance, Observation
from hiper_cli.types import Frame

__all__ = ["STAGES", "FrameResult", "Stage", "World", "make_stage"]


@dataclass
class World:
    """What the stages may read: live instances by uuid, per layer, and learned analyses."""

    background: dict[str, Instance] = field(default_factory=dict)
    foreground: dict[str, Instance] = field(default_factory=dict)
    analyses: list[Analysis] = field(default_factory=list)

    def layer(self, name: str) -> dict[str, Instance]:
        if name == "background":
            return self.background
        if name == "foreground":
            return self.foreground
        raise ConfigError(f"unknown layer {name!r}; expected 'background' or 'foreground'")

    def analysis(self, kind: str, class_name: str) -> Analysis | None:
        """The newest analysis of ``kind`` for ``class_name``, if any."""
        found = [a for a in self.analyses if a.kind == kind and a.class_name == class_name]
        return max(found, key=lambda a: a.created_s) if found else None

    def apply(self, result: FrameResult) -> None:
        for inst in result.instances:
            self.layer(inst.layer)[inst.uuid] = inst
        for uuid in result.deleted_instances:
            self.background.pop(uuid, None)
            self.foreground.pop(uuid, None)


@dataclass
class FrameResult:
    """What one stage made of one frame.

    ``instances`` are created or updated (upserted by uuid); ``deleted_instances`` are uuids
    merged away. ``timings_s`` holds named durations (e.g. ``background_s``) for reports.
    ``skipped`` is a reason when the stage did not process the frame (e.g. not a keyframe).
    """

    observations: list[Observation] = field(default_factory=list)
    instances: list[Instance] = field(default_factory=list)
    deleted_instances: list[str] = field(default_factory=list)
    timings_s: dict[str, float] = field(default_factory=dict)
    skipped: str | None = None

    def extend(self, other: FrameResult) -> None:
        self.observations.extend(other.observations)
        self.instances.extend(other.instances)
        self.deleted_instances.extend(other.deleted_instances)
        self.timings_s.update(other.timings_s)


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
