"""The options of ``hiper perceive``, and the checks that join them into ``PerceiveOptions``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from hiper_cli.cmdline.values import keep_duration_s
from hiper_cli.errors import ConfigError

if TYPE_CHECKING:
    from hiper_cli.pipeline import PerceiveOptions

Text = str | None
Stages = Annotated[Text, typer.Option(
    "--stages", help="Comma-separated stages (default: all available, background first).")]
Detector = Annotated[Text, typer.Option(
    "--detector", help="Foreground detector: yolox (default), a model of 'hiper models list', onnx:PATH, log "
    "or truth.")]
NoFilter = Annotated[bool, typer.Option(
    "--no-background-filter", help="Foreground: keep points of background instances.")]
Classes = Annotated[Text, typer.Option(
    "--classes", help="Foreground: only these detector classes, comma-separated (default all).")]
Exclude = Annotated[Text, typer.Option("--exclude-classes", help=(
    "Foreground: detector classes to drop, comma-separated (default: outdoor COCO classes and dining "
    'table; "" drops none).'))]
MappingHz = Annotated[float | None, typer.Option("--mapping-hz", help="Background keyframe rate in Hz.")]
MaxHz = Annotated[float | None, typer.Option("--max-hz", help=(
    "Perceive at most this many frames per second of log time; the others are skipped unread "
    "(default: every frame)."))]
DetectorHz = Annotated[float | None, typer.Option("--detector-hz", help=(
    "Run the detector this many times per second of log time and at keyframes; every frame is "
    "still tracked, named by the last look (default: every frame; 10 saves about a quarter of "
    "the CPU on a 30 Hz log)."))]
Options = Annotated[list[str] | None, typer.Option(
    "-o", "--option", help="Stage option STAGE.KEY=VALUE (repeatable).")]
Resume = Annotated[bool, typer.Option(
    "--resume", help="Redo the interrupted session of this log in its place.")]
Replace = Annotated[bool, typer.Option(
    "--replace", help="Drop this log's earlier session (one transaction), then perceive it again.")]
Again = Annotated[bool, typer.Option(
    "--again", help="Perceive a log the knowledge base holds already, as a new session.")]
Env = Annotated[Text, typer.Option("--env", help=(
    "Place (environment) name; default: the one place the knowledge base holds, or the log folder's "
    "name in a new one. A new name starts another place."))]
Align = Annotated[str, typer.Option("--align", help=(
    "How the log's poses join the place's map frame: auto (register its background to the map and "
    "correct its drift along its path; the first session defines the frame), none (its poses are map "
    "poses) or FILE (a 4x4 T_map_log)."))]
Keep = Annotated[str, typer.Option("--keep-observations", help=(
    "Keep raw observations this long before the newest stamp ('10 minutes', '2 h'); older ones that add "
    "nothing are summarised at the end of the session. 0 (default) summarises all (what hiper reanchor "
    "needs stays); 'all' keeps every observation."))]
View = Annotated[bool, typer.Option(
    "--view", help="Watch the run in a new Rerun viewer (pip install 'hiper\\[view]').")]
Timings = Annotated[bool, typer.Option(
    "--timings", help="Print the cost of each step per frame (always in --json, under 'steps').")]
Log = Annotated[Path, typer.Argument(help=(
    "Sensor log: TUM folder, .bag, rosbag2 folder or .mcap; or a running ROS 2 robot on rmw_zenoh: "
    "zenoh://tcp/HOST:PORT (pip install 'hiper\\[live]')."))]
IdleTimeout = Annotated[float | None, typer.Option(
    "--idle-timeout", help="Live: end the run after this many seconds without frames (default: Ctrl-C).")]
Queue = Annotated[int, typer.Option(
    "--queue", help="Live: frames that may wait to be perceived; beyond, the oldest is dropped.")]
LookAhead = Annotated[bool, typer.Option("--look-ahead", help=(
    "Live: take the next frame before perceiving this one, as for a log (the same knowledge base as "
    "the log, more frames/s, about twice the latency)."))]
Stats = Annotated[bool, typer.Option(
    "--stats", help="Live: print the latency from a frame being sent to being queryable (p50/p95).")]


def perceive_options(*, stages: str | None, option: list[str] | None, env: str | None, resume: bool,
                     replace: bool, again: bool, align: str, keep_observations: str, detector: str | None,
                     no_background_filter: bool, classes: str | None, exclude_classes: str | None,
                     mapping_hz: float | None, max_hz: float | None = None,
                     detector_hz: float | None = None) -> PerceiveOptions:
    """The flags as ``PerceiveOptions`` (each checked by ``PerceiveOptions.from_text``)."""
    from hiper_cli.pipeline import PerceiveOptions

    foreground = {"detector": detector, "background_filter": False if no_background_filter else None,
                  "classes": classes, "exclude_classes": exclude_classes, "detector_hz": detector_hz}
    if sum((resume, replace, again)) > 1:
        raise ConfigError("choose one of --resume, --replace and --again")
    return PerceiveOptions.from_text(
        stages=stages, options=option or [], env_name=env, resume=resume,
        on_existing="replace" if replace else "again" if again else "refuse", align=align,
        keep_observations_s=keep_duration_s(keep_observations), max_rate_hz=max_hz,
        overrides={"foreground": foreground, "background": {"keyframe_hz": mapping_hz}})


def check_source_flags(live: bool, source: Any, **given: Any) -> None:
    """Refuse a flag of a recorded log for a ``zenoh://`` source (``live``) and the reverse;
    ``given``: each flag's value, named as the parameter (``idle_timeout``, ``resume``, ...)."""
    live_only = {"--idle-timeout": given["idle_timeout"] is not None, "--queue": given["queue"] != 1,
                 "--look-ahead": given["look_ahead"], "--stats": given["stats"]}
    log_only = {"--resume": given["resume"], "--replace": given["replace"], "--again": given["again"],
                "--view": given["view"], "--max-hz": given.get("max_hz") is not None}
    wrong = [flag for flag, on in (log_only if live else live_only).items() if on]
    if wrong:
        kind, where = ("a recorded log", "a zenoh:// source") if live else ("a zenoh:// source", source)
        raise ConfigError(f"{wrong[0]} is for {kind}; drop it for {where}")


def open_viewer() -> Any:
    """``--view``: a new Rerun viewer that shows the run frame by frame (``view.live.LiveView``)."""
    from hiper_cli.view.live import LiveView

    return LiveView.open(spawn=True)
