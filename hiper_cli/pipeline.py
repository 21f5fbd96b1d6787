"""``hiper perceive``: stream a log's frames through the recognition stages into a knowledge base.

The pipeline owns the ``World``. Every frame's merged ``FrameResult`` (observations, upserted
and deleted instances) is written in one transaction together with the frame's pose row and
the session's progress, so a crash loses at most the frame in flight and ``resume=True``
continues after the last committed frame of the unfinished session of the same log. The scene
graph follows the documents every ``graph_sync_s`` seconds and at the end (see ``graph.kb``).

Each run is a session of an environment (default: the log folder's name); the environment's
live instances and analyses are loaded into the ``World`` first, so several logs of the same
place accumulate into one environment.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError, KnowledgeBaseError
from hiper_cli.graph import KnowledgeBase
from hiper_cli.graph.documents import Session
from hiper_cli.perceive.runner import prefetch, run_stages
from hiper_cli.perceive.stage import STAGES, FrameResult, Stage, make_stage, stage_names
from hiper_cli.types import Frame

__all__ = ["PerceiveSummary", "available_stages", "build_stages", "perceive"]

Progress = Callable[[int, int], None]


@dataclass
class PerceiveSummary:
    """What one ``perceive`` run did; ``to_dict`` is the ``--json`` summary."""

    log: str
    kb: str
    environment: str
    session_id: int
    stages: list[str]
    resumed_after_pose_id: int | None = None
    frames_total: int = 0
    frames_read: int = 0
    frames_already_done: int = 0
    skipped: list[dict[str, str]] = field(default_factory=list)
    seconds: float = 0.0
    observations: dict[str, dict[str, int]] = field(default_factory=dict)
    instances: dict[str, dict[str, int]] = field(default_factory=dict)
    deleted_instances: int = 0
    stage_mean_s: dict[str, float] = field(default_factory=dict)
    unavailable_stages: dict[str, str] = field(default_factory=dict)
    graph_sync_s: float = 0.0

    @property
    def frames_per_s(self) -> float:
        return self.frames_read / self.seconds if self.seconds > 0 else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "log": self.log,
            "kb": self.kb,
            "environment": self.environment,
            "session_id": self.session_id,
            "stages": self.stages,
            "unavailable_stages": self.unavailable_stages,
            "resumed_after_pose_id": self.resumed_after_pose_id,
            "frames_total": self.frames_total,
            "frames_read": self.frames_read,
            "frames_already_done": self.frames_already_done,
            "frames_skipped": len(self.skipped),
            "skipped": self.skipped,
            "seconds": round(self.seconds, 3),
            "frames_per_s": round(self.frames_per_s, 3),
            "observations": self.observations,
            "instances": self.instances,
            "deleted_instances": self.deleted_instances,
            "stage_mean_s": {k: round(v, 4) for k, v in self.stage_mean_s.items()},
            "graph_sync_s": round(self.graph_sync_s, 3),
        }


def available_stages() -> tuple[list[str], dict[str, str]]:
    """Registered stages whose modules are importable, and why the others are not."""
    import importlib.util

    ok: list[str] = []
    missing: dict[str, str] = {}
    for name, target in STAGES.items():
        module = target.split(":")[0]
        try:
            found = importlib.util.find_spec(module) is not None
        except ModuleNotFoundError:
            found = False
        if found:
            ok.append(name)
        else:
            missing[name] = f"stage {name!r} is not available in this version of hiper ({module} missing)"
    return ok, missing


def build_stages(
    names: Sequence[str] | None, log_path: Path, stage_options: Mapping[str, Mapping[str, Any]] | None = None
) -> tuple[list[Stage], dict[str, str]]:
    """Stages by name (registry order), each built with ``log_path`` and its options.

    ``names=None`` = every registered stage that is available and builds with its defaults; the
    others are reported in the second return value. A stage named explicitly, or given options,
    that cannot be built raises ``ConfigError``.
    """
    options = dict(stage_options or {})
    unavailable: dict[str, str] = {}
    if names is None:
        chosen, unavailable = available_stages()
    else:
        chosen = stage_names(list(names))
    unknown_options = sorted(set(options) - set(chosen))
    if unknown_options:
        raise ConfigError(
            f"options given for stage(s) {unknown_options} that do not run; "
            f"stages: {', '.join(chosen) or 'none'}"
        )
    stages: list[Stage] = []
    for name in chosen:
        try:
            stages.append(make_stage(name, log_path=log_path, **dict(options.get(name, {}))))
        except ConfigError as err:
            # a default stage that cannot run here (e.g. no detector model) is reported and
            # left out; one the user named or configured is an error
            if names is not None or name in options:
                raise
            unavailable[name] = str(err)
    return stages, unavailable


def _layer_class_counts(pairs: Counter[tuple[str, str]]) -> dict[str, dict[str, int]]:
    out: dict[str, dict[str, int]] = {}
    for (layer, cls), n in sorted(pairs.items()):
        out.setdefault(layer, {})[cls] = n
    return out


def perceive(
    log: Any,
    kb: KnowledgeBase,
    stages: Sequence[Stage] | Sequence[str] | None = None,
    stage_options: Mapping[str, Mapping[str, Any]] | None = None,
    *,
    poses: str | Path | None = None,
    log_path: Path | None = None,
    env_name: str | None = None,
    resume: bool = False,
    progress: Progress | None = None,
    graph_sync_s: float = 2.0,
    unavailable_stages: Mapping[str, str] | None = None,
) -> PerceiveSummary:
    """Run ``stages`` over the frames of ``log`` and store everything in ``kb``.

    ``log``: a path (opened with ``open_log(log, poses=poses)``) or a ``LogReader``.
    ``stages``: ``Stage`` objects, or registry names built with ``stage_options[name]`` and
    ``log_path`` (``None`` = every available stage). ``log_path`` names the log in the session
    (default: the path of ``log``); ``env_name`` the environment (default: the log folder's
    name). ``progress(done, total)`` is called after every frame.
    """
    if isinstance(log, str | Path):
        from hiper_cli.perceive.logs import open_log

        log_path = Path(log) if log_path is None else log_path
        log = open_log(log, poses=poses)
    path = Path(log_path if log_path is not None else log.info().path).resolve()
    if stages is None or all(isinstance(s, str) for s in stages):
        names_in = None if stages is None else [str(s) for s in stages]
        built, missing = build_stages(names_in, path, stage_options)
        stages = built
        unavailable_stages = {**missing, **dict(unavailable_stages or {})}
    stage_list = [s for s in stages if not isinstance(s, str)]
    env = kb.environment(env_name or path.stem or path.name)
    names = [s.name for s in stage_list]
    session: Session | None = None
    after_pose: int | None = None
    if resume:
        session = kb.resumable_session(env, str(path))
        if session is None:
            past = [s for s in kb.docs.sessions() if s.env_uuid == env.uuid and s.log_path == str(path)]
            if past:
                raise KnowledgeBaseError(
                    f"{path}: nothing to resume, its last session ({past[-1].id}) in environment "
                    f"{env.name!r} of {kb.location} finished; run without --resume to perceive it again"
                )
        else:
            after_pose = session.last_pose_id
    if session is None:
        session = kb.start_session(env, str(path), names)
    world = kb.load_world(env)
    total = len(log)
    summary = PerceiveSummary(
        log=str(path), kb=kb.location, environment=env.name, session_id=session.id, stages=names,
        resumed_after_pose_id=after_pose if resume else None, frames_total=total,
        unavailable_stages=dict(unavailable_stages or {}),
    )
    obs_counts: Counter[tuple[str, str]] = Counter()
    last_sync = time.perf_counter()
    current = session

    def frames() -> Iterator[Frame]:
        # Runs in the reading thread (``prefetch``): the only writer of frames_already_done.
        for frame in log:
            if after_pose is not None and frame.pose_id <= after_pose:
                summary.frames_already_done += 1
                continue
            yield frame

    def on_frame(frame: Frame | None, result: FrameResult) -> None:
        nonlocal last_sync
        if frame is None:
            kb.write_frame(current, result)
        else:
            kb.write_frame(current, result, pose_id=frame.pose_id, stamp_s=frame.stamp_s,
                           T_map_cam=frame.T_map_cam)
            summary.frames_read += 1
        for obs in result.observations:
            obs_counts[(obs.layer, obs.class_name)] += 1
        summary.deleted_instances += len(result.deleted_instances)
        now = time.perf_counter()
        if now - last_sync >= graph_sync_s:
            t0 = time.perf_counter()
            kb.sync_graph()
            summary.graph_sync_s += time.perf_counter() - t0
            last_sync = time.perf_counter()
        if progress is not None and frame is not None:
            progress(summary.frames_already_done + summary.frames_read, total)

    start = time.perf_counter()
    # Frames are read and decoded one thread ahead (decoding releases the interpreter lock):
    # with the `truth` or `log` detector the second core decodes while this one perceives.
    world, stats = run_stages(prefetch(frames()), stage_list, world, on_frame)
    kb.end_session(current)
    t0 = time.perf_counter()
    kb.sync_graph()
    summary.graph_sync_s += time.perf_counter() - t0
    summary.seconds = time.perf_counter() - start
    summary.skipped = [{"source": s, "reason": r} for s, r in getattr(log, "skipped", [])]
    summary.observations = _layer_class_counts(obs_counts)
    inst_counts: Counter[tuple[str, str]] = Counter()
    for layer in ("background", "foreground"):
        for inst in world.layer(layer).values():
            inst_counts[(layer, inst.class_name)] += 1
    summary.instances = _layer_class_counts(inst_counts)
    summary.stage_mean_s = {k: sum(v) / len(v) for k, v in stats.stage_times_s.items() if v}
    return summary
