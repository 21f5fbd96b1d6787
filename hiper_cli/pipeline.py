"""``hiper perceive``: stream a log's frames through the recognition stages into a knowledge base.

The pipeline owns the ``World``. Every frame's merged ``FrameResult`` (observations, upserted
and deleted instances) is written in one transaction together with the frame's pose row and
the session's progress, so a crash loses at most the frame in flight; ``resume`` redoes the
unfinished session of the same log in its place. Perceiving a log the environment already
holds with the same stages is refused unless asked for (``on_existing``). The scene
graph follows the documents every ``graph_sync_s`` seconds and at the end (see ``graph.kb``).

Each run is a session of an environment (default: the one place the knowledge base holds, or
for an empty one the log folder's name); the environment's live instances and analyses are
loaded into the ``World`` first, so several logs of the same place accumulate into one.

Two entries: ``perceive(reader, kb, stages, options)`` runs built stages over an open log;
``perceive_log(path, kb_location, LogOptions(...), PerceiveOptions(...))`` is the whole of
``hiper perceive`` (open the log, choose and build the stages, open the knowledge base, run).
"""

from __future__ import annotations

import json
import time
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError, KnowledgeBaseError
from hiper_cli.graph import KnowledgeBase
from hiper_cli.graph.compact import compact
from hiper_cli.graph.documents import Session
from hiper_cli.graph.history import FreeBefore, session_changes, snapshot
from hiper_cli.perceive.logs import LogOptions, LogReader, open_log
from hiper_cli.perceive.runner import prefetch, run_stages
from hiper_cli.perceive.stage import STAGES, FrameResult, Stage, make_stage, stage_names
from hiper_cli.session_align import MapCloudGrower, aligned, choose_alignment, correct_drift
from hiper_cli.types import Frame

__all__ = [
    "PerceiveOptions",
    "PerceiveSummary",
    "StageSet",
    "available_stages",
    "build_stages",
    "parse_stage_options",
    "perceive",
    "perceive_log",
    "select_stages",
]

Progress = Callable[[int, int], None]
DEFAULT_GRAPH_SYNC_S = 2.0  # the scene graph follows the documents this often during a run


def parse_stage_options(items: Sequence[str]) -> dict[str, dict[str, Any]]:
    """``["foreground.detector=truth", "background.keyframe_hz=2"]`` -> per-stage option dicts.

    Values are read as JSON when they parse (numbers, true/false, lists), else kept as text.
    """
    out: dict[str, dict[str, Any]] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        stage, dot, name = key.partition(".")
        if not sep or not dot or not stage or not name:
            raise ConfigError(f"-o {item!r}: expected STAGE.KEY=VALUE, e.g. -o foreground.detector=truth")
        try:
            value: Any = json.loads(raw)
        except ValueError:
            value = raw
        out.setdefault(stage, {})[name] = value
    return out


@dataclass(frozen=True)
class PerceiveOptions:
    """How one ``perceive`` run goes: which stages, their options, where the results go.

    ``stages``: registry names (``None`` = every available stage; options given for stages
    that are not available are then dropped, not errors). ``stage_options``: per stage, the
    keyword options of its factory, e.g. ``{"foreground": {"detector": "truth"}}``
    (``parse_stage_options`` reads them from ``-o STAGE.KEY=VALUE``). ``env_name``: the
    environment (default: the log folder's name). ``resume``: redo the interrupted session of
    this log in its place (from its first frame: the trackers' state is not stored, so
    continuing mid-log would split tracks; this gives the instances of an uninterrupted run).
    ``on_existing``: what to do with a log the environment holds already with the same stages:
    ``refuse``, ``replace`` (drop that session's data first, one transaction) or ``again`` (a
    new session on purpose). ``log_path`` names the log in the session (default: the reader's
    path).
    """

    stages: tuple[str, ...] | None = None
    stage_options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    env_name: str | None = None
    resume: bool = False
    on_existing: str = "refuse"
    log_path: Path | None = None
    graph_sync_s: float = DEFAULT_GRAPH_SYNC_S
    align: str = "auto"
    # raw observations kept this long before the newest stamp; older ones that add nothing are
    # summarised at the end of the session (``graph/compact.py``); None (the library's default;
    # ``hiper perceive`` summarises unless told otherwise) keeps every observation
    keep_observations_s: float | None = None
    # perceive at most this many frames per second of log time; the others are not decoded
    # (``IndexedLog.kept_ids``; a live source drops frames by itself); None: every frame
    max_rate_hz: float | None = None

    @classmethod
    def from_text(
        cls,
        *,
        stages: str | None = None,
        options: Sequence[str] = (),
        overrides: Mapping[str, Mapping[str, Any]] | None = None,
        env_name: str | None = None,
        resume: bool = False,
        on_existing: str = "refuse",
        align: str = "auto",
        keep_observations_s: float | None = None,
        max_rate_hz: float | None = None,
    ) -> PerceiveOptions:
        """From command-line text: ``stages`` comma-separated, ``options`` as ``STAGE.KEY=VALUE``.

        ``overrides[stage][key]`` beats the same ``-o`` key (a dedicated flag such as
        ``--detector``); an override whose value is ``None`` was not given and is ignored.
        """
        if env_name is not None and not env_name.strip():
            raise ConfigError(f"--env {env_name!r}: expected a name for the environment (default: the log "
                              "folder's name)")
        merged = parse_stage_options(options)
        for stage, values in (overrides or {}).items():
            for key, value in values.items():
                if value is not None:
                    merged.setdefault(stage, {})[key] = value
        if max_rate_hz is not None and not max_rate_hz > 0:
            raise ConfigError(f"--max-hz {max_rate_hz}: expected a rate above 0 frames per second")
        names = None if stages is None else tuple(s.strip() for s in stages.split(",") if s.strip())
        return cls(stages=names, stage_options=merged, env_name=env_name, resume=resume,
                   on_existing=on_existing, align=align, keep_observations_s=keep_observations_s,
                   max_rate_hz=max_rate_hz)


@dataclass(frozen=True)
class StageSet:
    """Built stages in run order, and why each registered stage left out cannot run here."""

    stages: tuple[Stage, ...]
    unavailable: Mapping[str, str] = field(default_factory=dict)


def select_stages(log_path: Path, options: PerceiveOptions) -> StageSet:
    """Build the stages ``options`` asks for; ``ConfigError`` when none can run."""
    stage_options = options.stage_options
    if options.stages is None:
        unknown = sorted(set(stage_options) - set(STAGES))
        if unknown:
            raise ConfigError(f"-o {unknown[0]}.…: no stage {unknown[0]!r}; expected one of "
                              f"{', '.join(STAGES)}")
        ok, _ = available_stages()
        stage_options = {k: v for k, v in stage_options.items() if k in ok}
    built, unavailable = build_stages(options.stages, log_path, stage_options)
    if not built:
        raise ConfigError(
            "no recognition stage is available in this version of hiper ("
            + "; ".join(unavailable.values()) + "); nothing to perceive"
        )
    return StageSet(tuple(built), unavailable)


def perceive_log(
    log: Path,
    kb: str,
    log_options: LogOptions | None = None,
    options: PerceiveOptions | None = None,
    *,
    kb_docs: Path | None = None,
    progress: Progress | None = None,
    on_start: Callable[[int], None] | None = None,
    on_frame: Callable[[Frame | None, FrameResult], None] | None = None,
) -> PerceiveSummary:
    """``hiper perceive`` in one call: open ``log``, build the stages, ``perceive`` into ``kb``.

    ``kb`` is a knowledge base location (see ``open_kb``; ``kb_docs`` its documents directory
    for an http:// endpoint). The log is opened and the stages built first, so bad options
    leave no knowledge base behind. ``on_start(total_frames)`` is called before the first frame,
    ``on_frame`` as in ``perceive``.
    """
    from hiper_cli.graph import open_kb

    options = options or PerceiveOptions()
    reader = _at_rate(open_log(log, log_options or LogOptions()), options.max_rate_hz)
    stages = select_stages(log.resolve(), options)
    if options.log_path is None:
        options = replace(options, log_path=log)
    with open_kb(kb, docs_dir=kb_docs) as knowledge:
        if on_start is not None:
            on_start(_frames_to_read(reader))
        return perceive(reader, knowledge, stages, options, progress=progress, on_frame=on_frame)


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
    # per step (the stages' named timings, ``kb_write_s``): total seconds and frames it ran in
    step_total_s: dict[str, float] = field(default_factory=dict)
    step_frames: dict[str, int] = field(default_factory=dict)
    # what the stages counted (``FrameResult.counts``): earlier sessions' objects found again,
    # moved or vacated
    counts: dict[str, int] = field(default_factory=dict)
    # the transform that carried the log into the place's map frame (``session_align.py``)
    alignment: dict[str, Any] | None = None
    changes: dict[str, int] = field(default_factory=dict)  # change events of the session, per kind
    storage: dict[str, Any] | None = None  # what the end-of-session compaction did

    def add_steps(self, timings_s: dict[str, float]) -> None:
        """Add one frame's step timings (names ending in ``_s``; others are counts)."""
        for name, seconds in timings_s.items():
            if name.endswith("_s"):
                self.step_total_s[name] = self.step_total_s.get(name, 0.0) + seconds
                self.step_frames[name] = self.step_frames.get(name, 0) + 1

    def steps(self) -> dict[str, dict[str, float]]:
        """Per step: frames it ran in, mean and total milliseconds, and mean per frame read."""
        read = max(self.frames_read, 1)
        return {
            name: {
                "frames": self.step_frames[name],
                "mean_ms": round(1000.0 * total / self.step_frames[name], 3),
                "per_frame_ms": round(1000.0 * total / read, 3),
                "total_s": round(total, 3),
            }
            for name, total in sorted(self.step_total_s.items())
        }

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
            "earlier_sessions": {k: self.counts.get(k, 0) for k in ("found_again", "moved", "vacated")},
            "stage_mean_s": {k: round(v, 4) for k, v in self.stage_mean_s.items()},
            "graph_sync_s": round(self.graph_sync_s, 3),
            "alignment": self.alignment,
            "changes": {k: self.changes.get(k, 0) for k in ("added", "removed", "moved")},
            "storage": self.storage,
            "steps": self.steps(),
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
    reader: LogReader,
    kb: KnowledgeBase,
    stages: StageSet | Sequence[Stage],
    options: PerceiveOptions | None = None,
    *,
    progress: Progress | None = None,
    on_frame: Callable[[Frame | None, FrameResult], None] | None = None,
) -> PerceiveSummary:
    """Run ``stages`` over the frames of ``reader`` and store everything in ``kb``.

    ``stages``: built stages, or a ``StageSet`` from ``select_stages`` (whose unavailable
    stages the summary reports). ``options.log_path`` names the log in the session (default:
    the reader's path); ``options.env_name`` the environment (default: the log folder's name).
    ``progress(done, total)`` is called after every frame. ``on_frame(frame, result)`` after
    each frame is written (and with ``frame=None`` for what the stages flush at the end), e.g.
    ``hiper_cli.view.live.LiveView`` to watch the run in Rerun.
    """
    options = options or PerceiveOptions()
    if isinstance(stages, StageSet):
        stage_list, unavailable_stages = list(stages.stages), dict(stages.unavailable)
    else:
        stage_list, unavailable_stages = list(stages), {}
    env_name, resume, graph_sync_s = options.env_name, options.resume, options.graph_sync_s
    live = bool(getattr(reader, "live", False))  # a running robot: no read-ahead, its URL names it
    reader = _at_rate(reader, options.max_rate_hz)
    source = options.log_path if options.log_path is not None else reader.info().path
    path = Path(source) if live else Path(source).resolve()
    log_name = str(source) if live else str(path)
    env = _environment_for(kb, env_name, path)
    names = [s.name for s in stage_list]
    _check_log_fits(reader, stage_list, path)
    alignment = choose_alignment(reader, kb, env, options.align, log_name)
    alignment, drift = correct_drift(reader, kb, env, alignment)
    session = _session_for(kb, env, log_name, names,
                           on_existing="resume" if resume else options.on_existing)
    kb.record_alignment(session, alignment)
    grower = MapCloudGrower(kb, env)
    for stage in stage_list:  # an object found where the place held something did not move there
        if hasattr(stage, "occupied_before"):
            stage.occupied_before = FreeBefore(grower.before).occupied
    world = kb.load_world(env)
    before = snapshot(world.foreground.values())
    total = _frames_to_read(reader)
    summary = PerceiveSummary(
        log=log_name, kb=kb.location, environment=env.name, session_id=session.id, stages=names,
        resumed_after_pose_id=None, frames_total=total,
        unavailable_stages=unavailable_stages, alignment=alignment.to_dict(),
    )
    obs_counts: Counter[tuple[str, str]] = Counter()
    last_sync = time.perf_counter()
    current = session

    def frames() -> Iterator[Frame]:
        yield from aligned(iter(reader), alignment, drift)

    hook = on_frame

    def write(frame: Frame | None, result: FrameResult) -> None:
        nonlocal last_sync
        t_write = time.perf_counter()
        if frame is None:
            kb.write_frame(current, result)
        else:
            kb.write_frame(current, result, pose_id=frame.pose_id, stamp_s=frame.stamp_s,
                           T_map_cam=frame.T_map_cam)
            summary.frames_read += 1
            grower.add(frame)
        summary.add_steps({**result.timings_s, "kb_write_s": time.perf_counter() - t_write})
        for obs in result.observations:
            obs_counts[(obs.layer, obs.class_name)] += 1
        summary.deleted_instances += len(result.deleted_instances)
        for name, n in result.counts.items():
            summary.counts[name] = summary.counts.get(name, 0) + n
        now = time.perf_counter()
        if now - last_sync >= graph_sync_s:
            t0 = time.perf_counter()
            kb.sync_graph()
            summary.graph_sync_s += time.perf_counter() - t0
            last_sync = time.perf_counter()
        if progress is not None and frame is not None:
            progress(summary.frames_already_done + summary.frames_read, total)
        if hook is not None:
            hook(frame, result)

    start = time.perf_counter()
    # Frames are read and decoded one thread ahead (decoding releases the interpreter lock):
    # with the `truth` or `log` detector the second core decodes while this one perceives.
    world, stats = run_stages(frames() if live else prefetch(frames()), stage_list, world, write,
                              look_ahead=bool(getattr(reader, "look_ahead", True)))
    grower.store()
    changes = session_changes(before, world.foreground.values(), current.id,
                              seen_before=FreeBefore(grower.before))
    kb.write_changes(current, changes)
    summary.changes = dict(Counter(c.kind for c in changes))
    kb.end_session(current)
    if options.keep_observations_s is not None:
        summary.storage = compact(kb, keep_raw_s=options.keep_observations_s).to_dict()
    t0 = time.perf_counter()
    kb.sync_graph()
    summary.graph_sync_s += time.perf_counter() - t0
    summary.seconds = time.perf_counter() - start
    summary.skipped = [{"source": s, "reason": r} for s, r in getattr(reader, "skipped", [])]
    summary.observations = _layer_class_counts(obs_counts)
    inst_counts: Counter[tuple[str, str]] = Counter()
    for layer in ("background", "foreground"):
        for inst in world.layer(layer).values():
            inst_counts[(layer, inst.class_name)] += 1
    summary.instances = _layer_class_counts(inst_counts)
    summary.stage_mean_s = {k: sum(v) / len(v) for k, v in stats.stage_times_s.items() if v}
    return summary


ON_EXISTING = ("refuse", "replace", "again", "resume")


def _frames_to_read(reader: LogReader) -> int:
    """How many frames iterating ``reader`` reads: those its rate keeps (``IndexedLog.kept_ids``)."""
    kept = getattr(reader, "kept_ids", None)
    return len(kept()) if callable(kept) else len(reader)


def _at_rate(reader: LogReader, max_rate_hz: float | None) -> LogReader:
    """``reader`` reading at most ``max_rate_hz`` frames per second of log time, where it can
    skip frames before decoding them (a recorded log); as it is otherwise."""
    if max_rate_hz is not None and hasattr(reader, "max_rate_hz"):
        setattr(reader, "max_rate_hz", max_rate_hz)  # noqa: B010 (not part of the LogReader protocol)
    return reader


def _environment_for(kb: KnowledgeBase, env_name: str | None, path: Path) -> Any:
    """The place a log joins: ``env_name`` when given (created on first use); else the one
    place the knowledge base holds (a lasting memory of one place needs no flag), or, in an
    empty knowledge base, one named after the log folder."""
    if env_name:
        return kb.environment(env_name)
    places = kb.environments()
    if len(places) == 1:
        return places[0]
    if not places:
        return kb.environment(path.stem or path.name)
    names = ", ".join(sorted(e.name for e in places))
    raise ConfigError(f"{kb.location} holds {len(places)} places ({names}); pass --env NAME to say which "
                      "one this log shows (a new name starts another place)")


def _check_log_fits(log: Any, stages: Sequence[Stage], path: Path) -> None:
    """Refuse, before a session is started, stages the log cannot feed."""
    if any(getattr(s, "needs_log_detections", False) for s in stages) and not log.info().has_detections:
        raise ConfigError(f"{path}: the log holds no detections, so --detector log has nothing to read; "
                          "pick another detector (yolox, truth, onnx:PATH)")


def _session_for(kb: KnowledgeBase, env: Any, log_path: str, names: list[str], *,
                 on_existing: str) -> Session:
    """The session to perceive ``log_path`` into, by ``on_existing`` (see ``perceive``)."""
    if on_existing not in ON_EXISTING:
        raise ConfigError(f"on_existing {on_existing!r}; expected one of {', '.join(ON_EXISTING)}")
    same = kb.sessions_of(env, log_path, names)
    if on_existing == "resume":
        unfinished = [s for s in kb.sessions_of(env, log_path) if not s.finished]
        if unfinished:
            return kb.restart_session(unfinished[-1])
        if same:
            raise KnowledgeBaseError(
                f"{log_path}: nothing to resume, its last session ({same[-1].id}) in environment "
                f"{env.name!r} of {kb.location} finished; run without --resume to perceive it again"
            )
        return kb.start_session(env, log_path, names)
    if same and on_existing == "replace":
        return kb.restart_session(same[-1])
    if same and on_existing == "refuse":
        last = same[-1]
        state = (f"finished with {last.frames} frames" if last.finished
                 else f"interrupted after {last.frames} frames")
        raise KnowledgeBaseError(
            f"{log_path}: already in {kb.location} (environment {env.name!r}, session {last.id}, {state}); "
            "pass --resume to finish an interrupted run, --replace to drop that session and perceive "
            "again, or --again for another session on purpose"
        )
    return kb.start_session(env, log_path, names)
