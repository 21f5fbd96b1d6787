"""The options of the ``hiper eval`` commands with many of them (qa, foreground)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

Opt = typer.Option

# hiper eval qa
QaLogs = Annotated[list[Path], typer.Argument(
    help="Logs with ground truth: hiper sim's gt/ or a world's gt/. Several are one benchmark: "
    "figures per log and over all their questions.")]
QaKb = Annotated[list[str] | None, Opt("--kb", help="Answer from this knowledge base (default: perceive the "
                                       "log); once per LOG, in order, for several logs.")]
QaDetector = Annotated[str, Opt("--detector", help=(
    "When perceiving: auto (truth where the log has gt/detections.jsonl, else yolox), truth, yolox, log "
    "or onnx:PATH."))]
QaOut = Annotated[Path | None, Opt("--out", "-o", help=(
    "Folder for questions.jsonl, answers.jsonl (and kb.hiper); with several logs, a folder per log in it."))]
ShortS = Annotated[float, Opt("--short-s", help="The short horizon: the last this many seconds.")]
QaSeed = Annotated[int, Opt("--seed", help="Seed of the generated question times.")]
GlimpseS = Annotated[float, Opt("--glimpse-s", help="An instance in view less than this many seconds is a "
                                "glimpse: counts are also scored with glimpses optional.")]

# hiper eval foreground
SimLog = Annotated[Path, typer.Argument(help="A log written by hiper sim (a TUM folder with gt/).")]
Detector = Annotated[str, Opt("--detector", help="truth, yolox, log or onnx:PATH.")]
BackgroundFilter = Annotated[bool, Opt(
    "--background-filter/--no-background-filter",
    help="Filter background boxes before clustering (off: the paper's ablation C4).")]
Ablation = Annotated[bool, Opt("--ablation/--no-ablation", help="Also run without background filter.")]
MaxFrames = Annotated[int, Opt("--max-frames", help="Stop after this many frames (0: all).")]
Background = Annotated[str, Opt("--background", help=(
    "stage (hiper's background recognition), truth (ground-truth boxes) or auto (the stage when "
    "available)."))]
Classes = Annotated[str | None, Opt("--classes", help=(
    "Only these detector classes name objects, comma-separated (a per-environment class list; "
    "default: all)."))]
ExcludeClasses = Annotated[str | None, Opt("--exclude-classes", help=(
    "Detector classes to drop, comma-separated (default: the indoor exclusion list of "
    "docs/foreground.md; \"\" drops none)."))]
Settings = Annotated[list[str], Opt(
    "--set", help="A foreground option KEY=VALUE (e.g. --set pixel_step=2); repeatable.")]
