"""``hiper eval foreground``: the paper's Table III beside ours on a ``hiper sim`` log."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._render import JSON_OPTION, console, print_json
from hiper_cli.commands.eval import eval_app


@eval_app.command("foreground")
def foreground(
    log: Annotated[Path, typer.Argument(help="A log written by hiper sim (a TUM folder with gt/).")],
    detector: str = typer.Option("truth", "--detector", help="truth, yolox, log or onnx:PATH."),
    background_filter: bool = typer.Option(
        True, "--background-filter/--no-background-filter",
        help="Filter background boxes before clustering (off: the paper's ablation C4).",
    ),
    ablation: bool = typer.Option(
        True, "--ablation/--no-ablation", help="Also run without background filter."
    ),
    max_frames: int = typer.Option(0, "--max-frames", help="Stop after this many frames (0: all)."),
    background: str = typer.Option(
        "auto", "--background", help="stage (hiper's background recognition), truth (ground-truth "
        "boxes) or auto (the stage when available)."
    ),
    classes: str | None = typer.Option(
        None, "--classes", help="Only these detector classes name objects, comma-separated (a per-"
        "environment class list; default: all).",
    ),
    exclude_classes: str | None = typer.Option(
        None, "--exclude-classes", help="Detector classes to drop, comma-separated (default: the "
        "indoor exclusion list of docs/foreground.md; \"\" drops none).",
    ),
    settings: list[str] = typer.Option(  # noqa: B008
        [], "--set", help="A foreground option KEY=VALUE (e.g. --set pixel_step=2); repeatable."
    ),
    json_out: bool = JSON_OPTION,
) -> None:
    """Foreground recognition and tracking against the ground truth (paper Table III).

    Example: hiper eval foreground out/hospital --detector yolox
    """
    from hiper_cli.evaluate.foreground import evaluate_foreground

    options = _parse_settings(settings)
    if classes is not None:
        options["classes"] = classes
    if exclude_classes is not None:
        options["exclude_classes"] = exclude_classes
    report = evaluate_foreground(
        log, detector=detector, background_filter=background_filter, ablation=ablation,
        max_frames=max_frames or None, background=background, **options,
    )
    if json_out:
        print_json(report)
        return
    _render(report)


def _parse_settings(settings: list[str]) -> dict[str, Any]:
    import json

    from hiper_cli.errors import ConfigError

    out: dict[str, Any] = {}
    for item in settings:
        key, sep, raw = item.partition("=")
        if not sep or not key:
            raise ConfigError(f"--set {item!r}: expected KEY=VALUE, e.g. --set pixel_step=2")
        try:
            out[key.strip()] = json.loads(raw)
        except json.JSONDecodeError:
            out[key.strip()] = raw
    return out


def _fmt(value: Any, digits: int = 3) -> str:
    if value is None:
        return "-"
    if isinstance(value, list | tuple):
        return "; ".join(_fmt(v, digits) for v in value)
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def _render(report: dict[str, Any]) -> None:
    from rich.table import Table

    ours, paper = report["ours"], report["paper"]

    def cols(key: str, digits: int = 3) -> list[str]:
        return [_fmt(paper[key][env], digits) for env in ("house", "hospital", "office")]

    title = (
        f"Foreground, {report['world'] or report['log']} (seed {report['seed']}), "
        f"detector {report['detector']}, background: {report['background_source']}"
    )
    if report.get("classes"):
        title += f"; classes: {', '.join(report['classes'])}"
    if report.get("exclude_classes"):
        title += f"; {len(report['exclude_classes'])} classes excluded"
    table = Table(title=title)
    for name in ("metric", "ours", "paper house", "paper hospital", "paper office"):
        table.add_column(name)
    classes = ", ".join(f"{c} {r['tp']}/{r['fp']}" for c, r in sorted(ours["classification"].items()))
    rows = [
        ("3D detect. time / s: mu; sigma", _fmt(ours["detect_time_s"]), *cols("detect_time_s")),
        ("classification i: TP; FP", f"{ours['tp']}; {ours['fp']}", *cols("classification_tp_fp")),
        ("  per class TP/FP", classes or "-", "", "", ""),
        ("FP share", _fmt(ours["fp_share"]), *cols("fp_share")),
        ("unknown instances", str(ours["unknown_instances"]), "", "", ""),
        ("sum i; sum o", f"{ours['sum_i']}; {ours['sum_o']}", *cols("sum_i_o")),
        ("loc. accuracy / m (classified obs.): mu; sigma", _fmt(ours["localisation_classified_m"]),
         *cols("localisation_m")),
        ("loc. accuracy / m (all obs.): mu; sigma; median", _fmt([*ours["localisation_visible_m"],
                                                                ours["localisation_visible_median_m"]]),
         "", "", ""),
        ("loc. accuracy / m (all obs., horizontal): mu; sigma", _fmt(ours["localisation_visible_xy_m"]),
         "", "", ""),
        ("loc. accuracy / m (true box centre): mu; sigma", _fmt(ours["localisation_box_centre_m"]),
         "", "", ""),
        ("people dyn. ratio", _fmt(ours["people_dynamic_ratio"]), *cols("people_dynamic_ratio")),
        ("people |v| / m/s: mu; sigma", _fmt(ours["people_speed_mps"]), *cols("people_speed_mps")),
        ("people CI / m/s: c_l; c_u", _fmt(ours["people_speed_ci_mps"]), *cols("people_speed_ci_mps")),
        ("moving people |v| ours vs truth / m/s", f"{_fmt(ours['moving_people_speed_mps'][0])} vs "
         f"{_fmt(ours['moving_people_true_speed_mps'][0])}", "true 0.6", "true 0.6", ""),
        ("identity switches", str(ours["identity_switches"]), "", "", ""),
        ("frames/s end to end", _fmt(ours["frames_per_s"], 1), "~10 (GPU)", "~10 (GPU)", "~10 (GPU)"),
    ]
    if "ablation" in report:
        ab = report["ablation"]
        rows.append(("C4 no background filter: detect. time / s", _fmt(ab["detect_time_s"]), "", "0.130", ""))
        rows.append(("C4 latency increase", _fmt(ab["latency_increase"]), "", "~0.69", ""))
        rows.append(("C4 FP share; sum i", f"{_fmt(ab['fp_share'])}; {ab['sum_i']}", "", "", ""))
    for row in rows:
        table.add_row(*row)
    console().print(table)
    console().print(f"{ours['frames']} frames; points per frame {ours['points_mean']:.0f}, "
                    f"after background filter {ours['points_after_background_mean']:.0f}")


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
