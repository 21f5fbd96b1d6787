"""``hiper eval foreground``: the paper's Table III beside ours on a ``hiper sim`` log."""

from __future__ import annotations

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.cmdline import eval as o
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import emit
from hiper_cli.render.evaluate import show_foreground_eval


@eval_app.command("foreground")
def foreground(log: o.SimLog, detector: o.Detector = "truth", background_filter: o.BackgroundFilter = True,
               ablation: o.Ablation = True, max_frames: o.MaxFrames = 0, background: o.Background = "auto",
               classes: o.Classes = None, exclude_classes: o.ExcludeClasses = None,
               settings: o.Settings = [],  # noqa: B006 (typer copies the default)
               json_out: Json = False) -> None:
    """Foreground recognition and tracking against the ground truth (paper Table III).

    Example: hiper eval foreground out/hospital --detector yolox
    """
    from hiper_cli.evaluate.foreground import evaluate_foreground, parse_settings

    options = parse_settings(settings, classes=classes, exclude_classes=exclude_classes)
    report = evaluate_foreground(log, detector=detector, background_filter=background_filter,
                                 ablation=ablation, max_frames=max_frames or None, background=background,
                                 **options)
    emit(report.to_dict(), json_out, show_foreground_eval)


def register(app: HiperTyper) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
