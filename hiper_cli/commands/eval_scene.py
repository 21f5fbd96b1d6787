"""``hiper eval scene``: a knowledge base scored against a realistic world's ground truth."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._common import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands._render import console, print_json, safe_text
from hiper_cli.commands.eval import eval_app


@eval_app.command(
    "scene",
    help=(
        "Score what a knowledge base holds of a log against the log's ground truth "
        "(gt/instances.json and gt/surface_points.npz: a realistic world's, or a hiper sim log's) "
        "and print Table II (background: semantic and static/dynamic precision, distance error, "
        "coverage of the observed wall and floor pieces) and Table III (foreground: TP/FP/FN per "
        "class, classified precision, centre error, "
        "unknown instances on no real object, person instances per person, walker speed). With "
        "--ceiling DETECTOR it also runs that detector (hiper eval detector) and prints hiper's recall "
        "of the nameable objects seen clearly beside the detector's own. --kb may also name a JSON "
        "export (hiper export --format json).\n\n"
        "Example: hiper perceive ../shared/worlds/bookstore --kb bs.hiper && "
        "hiper eval scene ../shared/worlds/bookstore --kb bs.hiper"
    ),
)
def eval_scene(
    log: Annotated[Path, typer.Argument(help="A log with a realistic world's gt/ folder.")],
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    ceiling: str | None = typer.Option(
        None, "--ceiling", help="Also score this detector's own recall (yolox, onnx:PATH, log, truth)."),
    json_out: bool = JSON_OPTION,
) -> None:
    from hiper_cli.evaluate import evaluate_kb

    data = evaluate_kb(kb, log, docs_dir=kb_docs, ceiling=ceiling).figures
    if json_out:
        print_json(data)
        return
    show_scene_eval(data)


def _f(value: Any) -> str:
    return "-" if value is None else f"{value:.3f}" if isinstance(value, float) else str(value)


def show_scene_eval(data: dict[str, Any]) -> None:
    """The two tables as text."""
    out = console()
    b, f = data["background"], data["foreground"]
    out.print(f"Table II, background ({safe_text(data['world'])}): {b['instances']} instances "
              f"({b['on_unlabelled']} on unlabelled geometry, {b['off_surface']} on no surface)")
    out.print(f"  semantic precision {_f(b['semantic_precision'])}   static/dynamic precision "
              f"{_f(b['static_precision'])}   centre distance mean/median {_f(b['distance_centre_mean_m'])}"
              f" / {_f(b['distance_centre_median_m'])} m")
    out.print(f"  coverage {_f(b['coverage'])} ({b['pieces_covered']} of {b['pieces']} observed pieces "
              f">= 1 m^2); uncovered: {safe_text(', '.join(b['uncovered']) or '-')}")
    out.print(f"  class->truth {safe_text(b['confusion'])}")
    out.print(f"Table III, foreground: {f['instances']} instances, TP {f['tp']} FP {f['fp']} FN(observed) "
              f"{f['fn_observed']}, precision {_f(f['precision'])}")
    out.print(f"  classified ('unknown' left out): TP {f['classified_tp']} FP {f['classified_fp']} precision "
              f"{_f(f['classified_precision'])} ({f['unknown']} unknown, "
              f"{_f(f['unknown_on_nothing'])} of them on no real object); person instances per person "
              f"{_f(f['persons_per_person'])}")
    out.print(f"  static/dynamic: {f['dynamic_instances']} dynamic instances; state of the matched ones "
              f"right {_f(f['state_accuracy'])}")
    for name, c in f["per_class"].items():
        out.print(f"  {safe_text(name):<14} TP {c['tp']:>3}  FP {c['fp']:>3}  FN {c['fn']:>3}")
    out.print(f"  unmatched, by what they lie on: {safe_text(f['unmatched'])}")
    c = data.get("detector_ceiling")
    if c is not None:
        out.print(f"  nameable objects seen clearly: hiper {c['hiper_found']} of {c['seen_clearly']}, the "
                  f"detector ({c['detector']}) alone {c['detector_found']} (its ceiling); hiper keeps "
                  f"{c['hiper_found_of_detector_found']} of the detector's {c['detector_found']}")
    out.print(f"  centre error (static, matched) mean/median {_f(f['centre_error_mean_m'])} / "
              f"{_f(f['centre_error_median_m'])} m; walkers matched {f['walkers_matched']}, speed mean "
              f"{_f(f['walker_speed_mean_mps'])} m/s, error {_f(f['walker_speed_error_mps'])} m/s")


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper eval``."""
