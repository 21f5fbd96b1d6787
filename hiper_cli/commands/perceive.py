"""``hiper perceive LOG --kb KB``: recognise what a sensor log shows and store it (``pipeline``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Json, Kb, KbDocs, with_log_flags
from hiper_cli.cmdline import perceive as o
from hiper_cli.commands._live import is_live, perceive_live_command
from hiper_cli.render import console, emit, frame_progress
from hiper_cli.render.perceive import show_run

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions


def perceive_command(
    log: o.Log, kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, stages: o.Stages = None,
    detector: o.Detector = None, no_background_filter: o.NoFilter = False, classes: o.Classes = None,
    exclude_classes: o.Exclude = None, mapping_hz: o.MappingHz = None, option: o.Options = None,
    resume: o.Resume = False, replace: o.Replace = False, again: o.Again = False, env: o.Env = None,
    align: o.Align = "auto", keep_observations: o.Keep = "0", view: o.View = False,
    timings: o.Timings = False, idle_timeout: o.IdleTimeout = None, queue: o.Queue = 1,
    look_ahead: o.LookAhead = False, stats: o.Stats = False, as_json: Json = False,
    max_hz: o.MaxHz = None, detector_hz: o.DetectorHz = None, *, log_options: LogOptions) -> None:
    """Stream a log's frames through the recognition stages into a knowledge base.

    Each frame's results are written atomically; an interrupted run continues with --resume.

    The log flags (camera, topics, frames, --poses) are those of hiper info. A zenoh:// source
    is a live robot (or hiper replay): frames are perceived as they come, the newest first when
    perception falls behind; --rgb-topic, --depth-topic, --info-topic, --pose-topic (/tf or an
    Odometry topic) choose what is read; Ctrl-C or --idle-timeout ends the session.

    Example: hiper perceive out/house --kb house.hiper --detector truth --timings

    Example: hiper perceive zenoh://tcp/127.0.0.1:7447 --kb live.hiper --idle-timeout 5 --stats
    """
    from hiper_cli.pipeline import perceive_log

    options = o.perceive_options(stages=stages, option=option, env=env, resume=resume, replace=replace,
        again=again, align=align, keep_observations=keep_observations, detector=detector,
        no_background_filter=no_background_filter, classes=classes, exclude_classes=exclude_classes,
        mapping_hz=mapping_hz, max_hz=max_hz, detector_hz=detector_hz)
    o.check_source_flags(is_live(log), log, idle_timeout=idle_timeout, queue=queue, look_ahead=look_ahead,
                         stats=stats, resume=resume, replace=replace, again=again, view=view, max_hz=max_hz)
    if is_live(log):
        return perceive_live_command(str(log), kb, kb_docs, log_options, options, queue=queue, stats=stats,
                                     idle_timeout_s=idle_timeout, look_ahead=look_ahead, as_json=as_json)
    live = o.open_viewer() if view else None  # without --view nothing of hiper_cli.view is imported
    with frame_progress("perceive", console(), enabled=not as_json) as bar:
        summary = perceive_log(log, kb, log_options, options, kb_docs=kb_docs, on_frame=live,
                               on_start=bar.start if bar else None, progress=bar.update if bar else None)
    if live is not None:
        live.close()
    emit(summary.to_dict(), as_json, lambda out, data: show_run(out, data, timings))


def register(app: HiperTyper) -> None:
    app.command("perceive")(with_log_flags(perceive_command))
