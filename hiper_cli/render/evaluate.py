"""What ``hiper eval`` shows: the paper's tables beside ours, detector ceilings, QA."""

from __future__ import annotations

from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_background_eval", "show_changes", "show_detector_ceiling", "show_feedback",
           "show_foreground_eval",
           "show_scene_eval"]


def _fmt(value: Any, digits: int = 3) -> str:
    if value is None:
        return "-"
    if isinstance(value, list | tuple):
        return "; ".join(_fmt(v, digits) for v in value)
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def show_foreground_eval(out: Any, report: dict[str, Any]) -> None:
    """``hiper eval foreground``: our Table III beside the paper's three environments."""
    from rich.table import Table

    ours, paper = report["ours"], report["paper"]

    def cols(key: str, digits: int = 3) -> list[str]:
        return [_fmt(paper[key][env], digits) for env in ("house", "hospital", "office")]

    title = (
        f"Foreground, {safe_text(report['world'] or report['log'])} (seed {report['seed']}), "
        f"detector {safe_text(report['detector'])}, "
        f"background: {safe_text(report['background_source'])}"
    )
    if report.get("classes"):
        title += f"; classes: {safe_text(', '.join(report['classes']))}"
    if report.get("exclude_classes"):
        title += f"; {len(report['exclude_classes'])} classes excluded"
    table = Table(title=title)
    for name in ("metric", "ours", "paper house", "paper hospital", "paper office"):
        table.add_column(name)
    classes = ", ".join(f"{safe_text(c)} {r['tp']}/{r['fp']}"
                        for c, r in sorted(ours["classification"].items()))
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
    out.print(table)
    out.print(f"{ours['frames']} frames; points per frame {ours['points_mean']:.0f}, "
                    f"after background filter {ours['points_after_background_mean']:.0f}")


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


def show_background_eval(out: Any, data: dict[str, Any]) -> None:
    """``hiper eval background``: our Table II rows beside the paper's and the targets."""
    from rich.table import Table

    world = safe_text(data['world'] or 'log')
    table = Table(title=f"Table II, {world} ({data['method']}, {data['keyframes']} "
                        f"keyframes of {data['frames']} frames)")
    for col in ("Description", "hiper", "paper", "target"):
        table.add_column(col)
    for row in _rows(data, data.get("paper")):
        table.add_row(*row)
    out.print(table)
    if data.get("unscored"):
        out.print(f"{data['unscored']} instances seen only in frames without an id image are left out "
                  "of the precisions (hiper eval scene scores every instance of a realistic world)")


def _f(value: Any) -> str:
    return "-" if value is None else f"{value:.3f}" if isinstance(value, float) else str(value)


def show_scene_eval(out: Any, data: dict[str, Any]) -> None:
    """``hiper eval scene``: Table II (background) and Table III (foreground) as text."""
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


def show_detector_ceiling(out: Any, data: dict[str, Any]) -> None:
    """``hiper eval detector``: per class the objects seen clearly and found, and the total."""
    from rich.table import Table

    table = Table("class", "seen clearly", "found", "share of frames", title=(
        f"{safe_text(data['detector'])} on {safe_text(data['log'])}: {data['frames']} labelled frames"))
    for name, row in data["per_class"].items():
        share = "-" if row["frame_share"] is None else f"{row['frame_share']:.2f}"
        table.add_row(safe_text(name), str(row["seen_clearly"]), str(row["found"]), share)
    total = data["total"]
    share = "-" if total["frame_share"] is None else f"{total['frame_share']:.2f}"
    table.add_row("[bold]total", str(total["seen_clearly"]), f"[bold]{total['found']}", share)
    out.print(table)


def show_feedback(out: Any, report: dict[str, Any]) -> None:
    """``hiper eval feedback``: false positives, switches and speed error per set of priors."""
    from rich.table import Table

    table = Table(
        "priors", "person TP", "person FP", "all FP", "FP share", "unknown", "ID switches",
        "speed error / m/s",
        title=f"feedback on {safe_text(report['log'])} (learned on {safe_text(report['learned_on'])})",
    )
    for name, r in report["runs"].items():
        err = r["moving_people_speed_error_mps"]
        share = r["fp_share"]
        table.add_row(
            safe_text(name), str(r["person_tp"]), str(r["person_fp"]), str(r["fp"]),
            "-" if share is None else f"{share:.3f}", str(r["unknown_instances"]),
            str(r["identity_switches"]), "-" if err is None else f"{err:+.3f}",
        )
    out.print(table)


def show_changes(out: Any, r: dict[str, Any]) -> None:
    """``hiper eval changes``: per kind of change, re-identification, ghosts, alignment, counts."""
    from rich.table import Table

    kinds = Table("change", "stored", "true", "matched", "precision", "recall", "F1")
    for kind, v in r["per_kind"].items():
        kinds.add_row(kind, str(v["stored"]), str(v["true"]), str(v["matched"]), f"{v['precision']:.2f}",
                      f"{v['recall']:.2f}", f"{v['f1']:.2f}")
    out.print(kinds)
    reid = "n/a" if r["reid_precision"] is None else f"{r['reid_precision']:.2f}"
    ghost = "n/a" if r["ghost_rate"] is None else f"{r['ghost_rate']:.2f}"
    out.print(f"re-identification precision {reid} ({r['reid_merged']} instances over sessions); ghost rate "
              f"{ghost} ({r['ghosts']} of {r['present_real']} present objects)")
    for a in r["alignment"]:
        at_start = (f" (at its start {a['error_start_m']:.3f} m, along its path <= "
                    f"{a['error_path_max_m']:.3f} m)" if "error_start_m" in a else "")
        out.print(f"session {a['session']} ({a['log']}): {a['method']}, fitness {a['fitness']:.2f}, error "
                  f"{a['error_m']:.3f} m / {a['error_deg']:.2f} deg{at_start}")
    counts = Table("class", "stored", "true", "error")
    for cls, v in r["counts"].items():
        counts.add_row(cls, str(v["stored"]), str(v["true"]), f"{v['error']:+d}")
    out.print(counts)
