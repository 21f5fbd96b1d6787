"""How the commands show their results to people: one ``show_*`` per result, rich tables.

Each takes the result's ``to_dict()`` form, the same data ``--json`` prints, so what a person
reads and what a machine reads cannot drift apart.
"""

from __future__ import annotations

from typing import Any

from hiper_cli.commands._render import safe_text

__all__ = [
    "show_background_eval",
    "show_bench_size",
    "show_foreground_eval",
    "show_kb_check",
    "show_kb_info",
    "show_log_info",
    "show_perceive",
    "show_steps",
]


def _skip(item: dict[str, Any]) -> str:
    return f"{safe_text(item['source'])}: {safe_text(item['reason'])}"


def show_perceive(out: Any, data: dict[str, Any]) -> None:
    """A ``perceive`` summary: frames, rate, stages not run, skipped frames, counts per class."""
    from rich.table import Table

    out.print(
        f"[bold]{data['frames_read']}[/] frames read, {data['frames_skipped']} skipped, "
        f"{data['frames_per_s']:.2f} frames/s -> {safe_text(data['kb'])} "
        f"(environment {safe_text(repr(data['environment']))}, "
        f"session {data['session_id']})"
    )
    align = data.get("alignment")
    if align and align["method"] == "registration":
        out.print(f"aligned to the place's map: fitness {align['fitness']:.2f}, rmse {align['rmse_m']:.3f} m")
    again = data.get("earlier_sessions", {})
    if any(again.values()):
        out.print(f"earlier sessions' objects: {again['found_again']} found again "
                  f"({again['moved']} moved), {again['vacated']} vacated")
    for name, why in data["unavailable_stages"].items():
        out.print(f"[yellow]stage {safe_text(name)} not run:[/] {safe_text(why)}")
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {_skip(item)}")
    table = Table("layer", "class", "observations", "instances")
    layers = sorted(set(data["observations"]) | set(data["instances"]))
    for layer in layers:
        classes = sorted(set(data["observations"].get(layer, {})) | set(data["instances"].get(layer, {})))
        for cls in classes:
            table.add_row(safe_text(layer), safe_text(cls),
                          str(data["observations"].get(layer, {}).get(cls, 0)),
                          str(data["instances"].get(layer, {}).get(cls, 0)))
    out.print(table)


def show_steps(out: Any, steps: dict[str, dict[str, float]]) -> None:
    """The cost of each step of a ``perceive`` run: mean per frame it ran in, per frame read."""
    from rich.table import Table

    table = Table("step", "frames", "mean ms", "per frame read ms", "total s")
    for name, row in steps.items():
        table.add_row(safe_text(name), str(row["frames"]), f"{row['mean_ms']:.2f}",
                      f"{row['per_frame_ms']:.2f}",
                      f"{row['total_s']:.2f}")
    out.print(table)


def show_log_info(out: Any, data: dict[str, Any]) -> None:
    """A log summary (``hiper info``): frames, rate, camera, pose source, gaps, skipped frames."""
    from rich.table import Table

    cam = data["camera"]
    title = f"{safe_text(data['path'])} ({safe_text(data['format'])})"
    table = Table(title=title, show_header=False)
    table.add_column("what", style="bold")
    table.add_column("value")
    rows = [
        ("frames", str(data["frames"])),
        ("rate", f"{data['rate_hz']:.3f} Hz"),
        ("duration", f"{data['duration_s']:.3f} s"),
        ("stamps", f"{data['first_stamp_s']:.6f} .. {data['last_stamp_s']:.6f}"),
        ("resolution", f"{cam['width']}×{cam['height']}"),
        ("intrinsics", f"fx {cam['fx']:.2f} fy {cam['fy']:.2f} cx {cam['cx']:.2f} cy {cam['cy']:.2f} "
                       f"depth scale {cam['depth_scale']:g}"
                       + (f" distortion {cam['distortion']}" if cam.get("distortion") else "")),
        ("pose source", safe_text(data["pose_source"])),
        ("detections", "yes" if data["has_detections"] else "no"),
        ("stamp gaps", ", ".join(f"{g['gap_s']:.3f} s after {g['after_stamp_s']:.3f}"
                                 for g in data["stamp_gaps"][:5])
         + (f" (+{len(data['stamp_gaps']) - 5} more)" if len(data["stamp_gaps"]) > 5 else "") or "none"),
    ]
    rows += [(f"source: {safe_text(role)}", safe_text(where)) for role, where in data["sources"].items()]
    if "readable_frames" in data:
        rows.append(("readable", f"{data['readable_frames']} of {data['frames']}"))
    rows.append(("skipped", str(len(data["skipped"]))))
    for name, value in rows:
        table.add_row(name, value)
    out.print(table)
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {_skip(item)}")
    if len(data["skipped"]) > 10:
        out.print(f"[yellow]... {len(data['skipped']) - 10} more skipped[/]")
    if data.get("frame_list"):
        frames = Table(title="frames")
        for column in ("pose_id", "stamp_s", "x y z qx qy qz qw"):
            frames.add_column(column)
        for item in data["frame_list"]:
            frames.add_row(str(item["pose_id"]), f"{item['stamp_s']:.6f}",
                           " ".join(f"{v:.4f}" for v in item["pose_xyz_qxyzw"]))
        out.print(frames)


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


def show_kb_info(out: Any, data: dict[str, Any]) -> None:
    """``hiper kb info``: totals, counts per type, layer and class, and the sessions."""
    from rich.table import Table

    totals = data["totals"]
    out.print(
        f"[bold]{safe_text(data['kb'])}[/]: {totals['observation']} observations, "
        f"{totals['instance']} instances, "
        f"{totals['analysis']} analyses, {totals['environment']} environments, "
        f"{data['size_bytes'] / 1e6:.1f} MB on disk"
    )
    table = Table("type", "layer", "class", "count")
    for c in data["counts"]:
        table.add_row(safe_text(c["type"]), safe_text(c["layer"] or ""), safe_text(c["class"] or ""),
                      str(c["count"]))
    out.print(table)
    sessions = Table("session", "log", "frames", "finished")
    for s in data["sessions"]:
        sessions.add_row(str(s["id"]), safe_text(s["log_path"]), str(s["frames"]),
                         "yes" if s["ended_s"] else "no")
    if data["sessions"]:
        out.print(sessions)


def show_sessions(out: Any, rows: list[dict[str, Any]]) -> None:
    """``hiper kb sessions``: one row per session, with its log stamps and alignment."""
    import datetime

    from rich.table import Table

    def clock(t: float | None) -> str:
        stamp = datetime.datetime.fromtimestamp(t or 0.0, datetime.UTC)
        return "" if t is None else stamp.strftime("%Y-%m-%d %H:%M")

    def span(s: dict[str, Any]) -> str:
        first, last = s["first_stamp_s"], s["last_stamp_s"]
        return "" if first is None else f"{first:.1f}-{last:.1f}"

    def aligned(a: dict[str, Any] | None) -> str:
        return "" if a is None else f"{a['method']} (fitness {a['fitness']:.2f})"

    table = Table("session", "place", "log", "frames", "stamps (s)", "started (UTC)", "alignment")
    for s in rows:
        table.add_row(str(s["id"]), s["environment"], s["log_path"], str(s["frames"]), span(s),
                      clock(s["started_s"]) + ("" if s["ended_s"] else " (unfinished)"),
                      aligned(s["alignment"]))
    out.print(table if rows else "no sessions")


def show_bench_size(out: Any, r: dict[str, Any]) -> None:
    """One size of ``hiper kb bench``: ingest rates, peak memory and p50/p95 latencies."""
    lat = "  ".join(f"{k} {v['p50_ms']:.2f}/{v['p95_ms']:.2f} ms" for k, v in r["latency"].items())
    follower = (f" + follower {r['follower_peak_rss_mb']:.0f} MB" if r["follower_peak_rss_mb"] else "")
    out.print(
        f"[bold]{r['observations']:>8}[/] obs: documents {r['ingest_obs_per_s']:.0f}/s "
        f"({r['ingest_obs_per_cpu_s']:.0f}/CPU-s), graph {r['graph_sync_obs_per_s']:.0f}/s "
        f"({safe_text(r['graph'])}), end to end {r['end_to_end_obs_per_s']:.0f}/s, peak RSS "
        f"{r['peak_rss_mb']:.0f} MB{follower}, load {r['load_average_1min']}\n    p50/p95: {lat}"
    )


def show_kb_check(out: Any, data: dict[str, Any]) -> None:
    """``hiper kb check``: each problem found, whether the graph was rebuilt, the verdict."""
    for problem in data["problems"]:
        out.print(f"[yellow]problem:[/] {safe_text(problem)}")
    if data["repaired"]:
        out.print("graph rebuilt from the documents")
    out.print("[green]consistent[/]" if data["ok"] else "[red]inconsistent[/]")
