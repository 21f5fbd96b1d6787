"""``hiper perceive LOG --kb KB``: recognise what a sensor log shows and store it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._log_options import open_log_from_flags, with_log_flags
from hiper_cli.commands._render import JSON_OPTION, console, print_json
from hiper_cli.errors import ConfigError

__all__ = ["KB_DOCS_HELP", "KB_HELP", "parse_stage_options", "register"]

KB_HELP = "Knowledge base: a directory, or the http:// URL of a SPARQL endpoint holding the scene graph."
KB_DOCS_HELP = "Documents directory when --kb is an http:// endpoint (default ./scene.hiper)."


def parse_stage_options(items: list[str]) -> dict[str, dict[str, Any]]:
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


def perceive_command(
    log: Annotated[Path, typer.Argument(help="Sensor log: TUM folder, .bag, rosbag2 folder or .mcap.")],
    kb: Annotated[str, typer.Option("--kb", help=KB_HELP)] = "scene.hiper",
    kb_docs: Annotated[Path | None, typer.Option("--kb-docs", help=KB_DOCS_HELP)] = None,
    stages: Annotated[
        str | None,
        typer.Option("--stages", help="Comma-separated stages (default: all available, background first)."),
    ] = None,
    detector: Annotated[
        str | None,
        typer.Option("--detector", help="Foreground detector: yolox (default), onnx:PATH, log or truth."),
    ] = None,
    no_background_filter: Annotated[
        bool, typer.Option("--no-background-filter", help="Foreground: keep points of background instances.")
    ] = False,
    classes: Annotated[
        str | None,
        typer.Option(
            "--classes", help="Foreground: only these detector classes, comma-separated (default all)."
        ),
    ] = None,
    exclude_classes: Annotated[
        str | None,
        typer.Option(
            "--exclude-classes",
            help="Foreground: detector classes to drop, comma-separated (default: outdoor COCO classes and "
            "dining table; \"\" drops none).",
        ),
    ] = None,
    mapping_hz: Annotated[
        float | None, typer.Option("--mapping-hz", help="Background keyframe rate in Hz.")
    ] = None,
    option: Annotated[
        list[str] | None, typer.Option("-o", "--option", help="Stage option STAGE.KEY=VALUE (repeatable).")
    ] = None,
    resume: Annotated[
        bool, typer.Option("--resume", help="Continue the unfinished session of this log.")
    ] = False,
    env: Annotated[
        str | None, typer.Option("--env", help="Environment name (default: the log folder's name).")
    ] = None,
    as_json: bool = JSON_OPTION,
    log_flags: dict[str, Any] | None = None,
) -> None:
    """Stream a log's frames through the recognition stages into a knowledge base.

    Each frame's results are written atomically; an interrupted run continues with --resume.

    The log flags (camera, topics, frames, --poses) are those of hiper info.

    Example: hiper perceive out/house --kb house.hiper --detector truth
    """
    from hiper_cli.graph import open_kb
    from hiper_cli.pipeline import build_stages, perceive

    options = parse_stage_options(option or [])
    if detector is not None:
        options.setdefault("foreground", {})["detector"] = detector
    if no_background_filter:
        options.setdefault("foreground", {})["background_filter"] = False
    if classes is not None:
        options.setdefault("foreground", {})["classes"] = classes
    if exclude_classes is not None:
        options.setdefault("foreground", {})["exclude_classes"] = exclude_classes
    if mapping_hz is not None:
        options.setdefault("background", {})["keyframe_hz"] = mapping_hz
    names = None if stages is None else [s.strip() for s in stages.split(",") if s.strip()]
    reader = open_log_from_flags(log, **(log_flags or {}))
    if names is None:  # flags for stages that are not available are dropped, not errors
        from hiper_cli.pipeline import available_stages

        ok, _ = available_stages()
        options = {k: v for k, v in options.items() if k in ok}
    built, unavailable = build_stages(names, log.resolve(), options)
    if not built:
        raise ConfigError(
            "no recognition stage is available in this version of hiper ("
            + "; ".join(unavailable.values()) + "); nothing to perceive"
        )
    out = console()
    with open_kb(kb, docs_dir=kb_docs) as knowledge:
        if as_json:
            summary = perceive(reader, knowledge, built, log_path=log, env_name=env, resume=resume,
                               unavailable_stages=unavailable)
        else:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            with Progress(
                TextColumn("[bold]perceive"), BarColumn(), MofNCompleteColumn(),
                TextColumn("{task.fields[rate]:.1f} frames/s"), TimeElapsedColumn(), console=out,
            ) as bar:
                task = bar.add_task("frames", total=len(reader), rate=0.0)

                def progress(done: int, total: int) -> None:
                    elapsed = bar.tasks[0].elapsed or 0.0
                    bar.update(task, completed=done, rate=done / elapsed if elapsed > 0 else 0.0)

                summary = perceive(reader, knowledge, built, log_path=log, env_name=env, resume=resume,
                                   progress=progress, unavailable_stages=unavailable)
    data = summary.to_dict()
    if as_json:
        print_json(data)
        return
    _render(out, data)


def _render(out: Any, data: dict[str, Any]) -> None:
    from rich.table import Table

    out.print(
        f"[bold]{data['frames_read']}[/] frames read, {data['frames_skipped']} skipped, "
        f"{data['frames_per_s']:.2f} frames/s -> {data['kb']} (environment {data['environment']!r}, "
        f"session {data['session_id']})"
    )
    for name, why in data["unavailable_stages"].items():
        out.print(f"[yellow]stage {name} not run:[/] {why}")
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {item['source']}: {item['reason']}")
    table = Table("layer", "class", "observations", "instances")
    layers = sorted(set(data["observations"]) | set(data["instances"]))
    for layer in layers:
        classes = sorted(set(data["observations"].get(layer, {})) | set(data["instances"].get(layer, {})))
        for cls in classes:
            table.add_row(layer, cls, str(data["observations"].get(layer, {}).get(cls, 0)),
                          str(data["instances"].get(layer, {}).get(cls, 0)))
    out.print(table)


def register(app: typer.Typer) -> None:
    app.command("perceive")(with_log_flags(perceive_command))
