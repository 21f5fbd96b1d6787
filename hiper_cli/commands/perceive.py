"""``hiper perceive LOG --kb KB``: recognise what a sensor log shows and store it."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption, with_log_flags
from hiper_cli.commands._render import console, frame_progress, print_json

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions

__all__ = ["register"]

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
    "How the log's poses join the place's map frame: auto (register its background to the map; the "
    "first session defines the frame), none (its poses are map poses) or FILE (a 4x4 T_map_log)."))]
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


def perceive_command(
    log: Log, kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None, stages: Stages = None,
    detector: Detector = None, no_background_filter: NoFilter = False, classes: Classes = None,
    exclude_classes: Exclude = None, mapping_hz: MappingHz = None, option: Options = None,
    resume: Resume = False, replace: Replace = False, again: Again = False, env: Env = None,
    align: Align = "auto", keep_observations: Keep = "0", view: View = False, timings: Timings = False,
    idle_timeout: IdleTimeout = None, queue: Queue = 1, look_ahead: LookAhead = False, stats: Stats = False,
    as_json: bool = JSON_OPTION, *,
    log_options: LogOptions,
) -> None:
    """Stream a log's frames through the recognition stages into a knowledge base.

    Each frame's results are written atomically; an interrupted run continues with --resume.

    The log flags (camera, topics, frames, --poses) are those of hiper info. A zenoh:// source
    is a live robot (or hiper replay): frames are perceived as they come, the newest first when
    perception falls behind; --rgb-topic, --depth-topic, --info-topic, --pose-topic (/tf or an
    Odometry topic) choose what is read; Ctrl-C or --idle-timeout ends the session.

    Example: hiper perceive out/house --kb house.hiper --detector truth --timings

    Example: hiper perceive zenoh://tcp/127.0.0.1:7447 --kb live.hiper --idle-timeout 5 --stats
    """
    from hiper_cli.pipeline import PerceiveOptions, perceive_log

    foreground = {"detector": detector, "background_filter": False if no_background_filter else None,
                  "classes": classes, "exclude_classes": exclude_classes}
    if sum((resume, replace, again)) > 1:
        from hiper_cli.errors import ConfigError

        raise ConfigError("choose one of --resume, --replace and --again")
    options = PerceiveOptions.from_text(
        stages=stages, options=option or [], env_name=env, resume=resume,
        on_existing="replace" if replace else "again" if again else "refuse", align=align,
        keep_observations_s=keep_duration_s(keep_observations),
        overrides={"foreground": foreground, "background": {"keyframe_hz": mapping_hz}})
    from hiper_cli.commands._live import is_live, perceive_live_command
    from hiper_cli.errors import ConfigError

    live_only = {"--idle-timeout": idle_timeout is not None, "--queue": queue != 1,
                 "--look-ahead": look_ahead, "--stats": stats}
    log_only = {"--resume": resume, "--replace": replace, "--again": again, "--view": view}
    wrong = [flag for flag, given in (log_only if is_live(log) else live_only).items() if given]
    if wrong:
        kind, source = ("a recorded log", "a zenoh:// source") if is_live(log) else ("a zenoh:// source", log)
        raise ConfigError(f"{wrong[0]} is for {kind}; drop it for {source}")
    if is_live(log):
        perceive_live_command(str(log), kb, kb_docs, log_options, options, queue=queue,
                              idle_timeout_s=idle_timeout, look_ahead=look_ahead, stats=stats,
                              as_json=as_json)
        return
    out = console()
    live = None
    if view:  # without --view nothing of hiper_cli.view is imported or run
        from hiper_cli.view.live import LiveView

        live = LiveView.open(spawn=True)
    with frame_progress("perceive", out, enabled=not as_json) as bar:
        summary = perceive_log(log, kb, log_options, options, kb_docs=kb_docs, on_frame=live,
                               on_start=bar.start if bar else None, progress=bar.update if bar else None)
    if live is not None:
        live.close()
    if as_json:
        print_json(summary.to_dict())
    else:
        from hiper_cli.commands._tables import show_perceive, show_steps

        show_perceive(out, summary.to_dict())
        if timings:
            show_steps(out, summary.to_dict()["steps"])


def keep_duration_s(text: str) -> float | None:
    """``--keep-observations``: seconds, or None for 'all' (no summarising)."""
    if text.strip().lower() in ("all", "forever", "none"):
        return None
    try:
        return max(0.0, float(text))
    except ValueError:
        pass
    from hiper_cli.agent.times import resolve_span_s
    from hiper_cli.errors import ConfigError, QueryError

    try:
        return resolve_span_s(text)
    except QueryError as err:
        raise ConfigError(f"--keep-observations {text!r}: expected a duration such as '10 minutes', "
                          "'2 h', 0 or 'all'") from err


def register(app: typer.Typer) -> None:
    app.command("perceive")(with_log_flags(perceive_command))
