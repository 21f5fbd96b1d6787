"""``hiper eval feedback``: false positives with and without the learned priors (C2)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.cmdline import eval as o
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import emit
from hiper_cli.render.evaluate import show_feedback

Log = Annotated[Path, typer.Argument(help="A hiper sim log to perceive with the learned priors.")]
Learn = Annotated[Path, typer.Option("--learn", help="A hiper sim log of the same world to learn them on.")]
Background = Annotated[str, typer.Option("--background", help="truth (ground-truth boxes) or stage.")]


@eval_app.command("feedback")
def feedback(log: Log, learn: Learn, detector: o.Detector = "truth", background: Background = "truth",
             settings: o.Settings = [],  # noqa: B006 (typer copies the default)
             json_out: Json = False) -> None:
    """Learn ODS, size and altitude on --learn, then perceive LOG with all priors, each prior
    alone and none (the paper's C2): person false positives (pictures and TV screens showing
    people), identity switches and speed error per setting.

    Example: hiper eval feedback out/hospital_b --learn out/hospital_a
    """
    from hiper_cli.analyze.feedback import evaluate_feedback
    from hiper_cli.evaluate.foreground import parse_settings

    options = parse_settings(settings)
    report = evaluate_feedback(log, learn, detector=detector, background=background, **options)
    emit(report, json_out, show_feedback)


def register(app: HiperTyper) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
