"""``hiper eval background``: Table II of the paper (background reconstruction), ours beside it."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._render import JSON_OPTION, console, print_json
from hiper_cli.commands.eval import eval_app


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper eval``."""


def _pct(v: Any) -> str:
    return "—" if v is None else f"{100.0 * v:.1f}"


def _pair(a: Any, b: Any, fmt: str = "{}") -> str:
    if a is None or b is None:
        return "N/A"
    return f"{fmt.format(a)}; {fmt.format(b)}"


def _rows(r: dict[str, Any], p: dict[str, Any] | None) -> list[tuple[str, str, str, str]]:
    p = p or {}

    def both(a: str, b: str, fmt: str = "{}") -> tuple[str, str]:
        return _pair(r[a], r[b], fmt), _pair(p.get(a), p.get(b), fmt)

    def one(key: str) -> tuple[str, str]:
        return str(r[key]), str(p.get(key, ""))

    def pct(key: str) -> tuple[str, str]:
        return _pct(r[key]), _pct(p.get(key))

    return [
        ("Processing time / s: μ; σ (CPU, 1 thread)", *both("time_mean_s", "time_std_s", "{:.3f}"), "≤ 0.05"),
        ("Processing time / s: μ; σ (wall)", _pair(r["wall_mean_s"], r["wall_std_s"], "{:.3f}"), "", ""),
        ("Sum: i; o", *both("instances", "observations"), ""),
        ("Precision stat./dyn. / %", *pct("static_precision"), "≥ 99.5"),
        ("Precision semantics / %", *pct("semantic_precision"), "≥ 90"),
        ("Walls: TP; FP", *both("walls_tp", "walls_fp"), ""),
        ("Tables: TP; FP", *both("tables_tp", "tables_fp"), ""),
        ("Furniture: FP", *one("furniture_fp"), ""),
        ("Door, door frame: FP", *one("door_fp"), ""),
        ("Foreground instances: FP", *one("foreground_fp"), ""),
        ("Background / m: μ; σ", *both("distance_mean_m", "distance_std_m", "{:.3f}"), "≤ 0.02"),
        ("Floors; ceilings: TP", _pair(r["floors_tp"], r["ceilings_tp"]), "(added by hand)", ""),
        ("Truth walls found", f"{r['truth_walls_found']} of {r['truth_walls']}", "", ""),
        ("Truth tables found", f"{r['truth_tables_found']} of {r['truth_tables']}", "", ""),
    ]


@eval_app.command(
    "background",
    help=(
        "Run background recognition over a hiper sim log (its mapping phase) and print the paper's "
        "Table II rows beside ours: processing time per keyframe, instance and observation counts, "
        "static/dynamic and semantic precision, walls and tables TP/FP, furniture and door false "
        "positives, and the distance of our planes to the true surfaces.\n\n"
        "Example: hiper eval background out/house --method ransac"
    ),
)
def eval_background(
    log: Annotated[Path, typer.Argument(help="A log written by hiper sim (with gt/).")],
    method: str = typer.Option("fast", "--method", "-m", help="Plane extractor: fast or ransac."),
    all_phases: bool = typer.Option(
        False, "--all-phases", help="Use every frame, not only the mapping phase (people then appear)."
    ),
    max_frames: int | None = typer.Option(None, "--max-frames", help="Stop after this many frames."),
    keyframe_hz: float = typer.Option(2.0, "--keyframe-hz", help="Mapping rate (the paper: 2 Hz)."),
    json_out: bool = JSON_OPTION,
) -> None:
    # one core: keep BLAS and OpenMP (open3d) single-threaded; set before numpy loads
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from hiper_cli.evaluate.background import evaluate_background

    report = evaluate_background(
        log, method=method, phase=None if all_phases else "mapping", max_frames=max_frames,
        keyframe_hz=keyframe_hz,
    )
    data = report.to_dict()
    if json_out:
        print_json(data)
        return
    from rich.table import Table

    table = Table(title=f"Table II, {report.world or 'log'} ({report.method}, {report.keyframes} keyframes "
                        f"of {report.frames} frames)")
    for col in ("Description", "hiper", "paper", "target"):
        table.add_column(col)
    for row in _rows(data, data.get("paper")):
        table.add_row(*row)
    console().print(table)
