"""``hiper eval feedback``: false positives with and without the learned priors (C2)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import console, print_json, safe_text
from hiper_cli.commands.eval import eval_app


@eval_app.command("feedback")
def feedback(
    log: Annotated[Path, typer.Argument(help="A hiper sim log to perceive with the learned priors.")],
    learn: Annotated[
        Path, typer.Option("--learn", help="A hiper sim log of the same world to learn them on.")
    ],
    detector: str = typer.Option("truth", "--detector", help="truth, yolox, log or onnx:PATH."),
    background: str = typer.Option("truth", "--background", help="truth (ground-truth boxes) or stage."),
    settings: list[str] = typer.Option(  # noqa: B008
        [], "--set", help="A foreground option KEY=VALUE (e.g. --set pixel_step=2); repeatable."
    ),
    json_out: bool = JSON_OPTION,
) -> None:
    """Learn ODS, size and altitude on --learn, then perceive LOG with all priors, each prior
    alone and none (the paper's C2): person false positives (pictures and TV screens showing
    people), identity switches and speed error per setting.

    Example: hiper eval feedback out/hospital_b --learn out/hospital_a
    """
    from hiper_cli.analyze.feedback import evaluate_feedback
    from hiper_cli.evaluate.foreground import parse_settings

    report = evaluate_feedback(
        log, learn, detector=detector, background=background, **parse_settings(settings)
    )
    if json_out:
        print_json(report)
        return
    from rich.table import Table

    table = Table(
        "priors",
        "person TP",
        "person FP",
        "all FP",
        "FP share",
        "unknown",
        "ID switches",
        "speed error / m/s",
        title=f"feedback on {safe_text(report['log'])} (learned on {safe_text(report['learned_on'])})",
    )
    for name, r in report["runs"].items():
        err = r["moving_people_speed_error_mps"]
        share = r["fp_share"]
        table.add_row(
            safe_text(name),
            str(r["person_tp"]),
            str(r["person_fp"]),
            str(r["fp"]),
            "-" if share is None else f"{share:.3f}",
            str(r["unknown_instances"]),
            str(r["identity_switches"]),
            "-" if err is None else f"{err:+.3f}",
        )
    console().print(table)


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
