"""The benchmark's report: one Markdown file with PNG figures (matplotlib, the ``plot`` extra).

Per world: box plots of the task times per configuration (Figure 7 of the paper), the success
rates, and the C1 heatmaps the tasks used; then Tables II and III beside the paper's numbers and
the exact command and seeds that reproduce the run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.bench.run import BenchResult
from hiper_cli.bench.tasks import TASKS
from hiper_cli.errors import ConfigError

__all__ = ["require_matplotlib", "write_report"]

_TASK_NAMES = {"T1": "T1 find person", "T2": "T2 find bottle", "T3": "T3 grasp", "T4": "T4 carry back"}


def require_matplotlib() -> Any:
    """``matplotlib.pyplot`` with the Agg backend, or a one-line fix."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as err:
        raise ConfigError("hiper bench needs matplotlib for its figures: pip install 'hiper[plot]'") from err
    return plt


def _times_plot(plt: Any, summary: dict[str, Any], world: str, path: Path) -> None:
    cells = summary["tasks"][world]
    configs = list(cells)
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.4))
    for ax, task in zip(axes, TASKS, strict=True):
        data = [cells[c][task]["times_s"] or [np.nan] for c in configs]
        ax.boxplot(data, tick_labels=configs, showfliers=True)
        ax.set_title(_TASK_NAMES[task])
        ax.set_ylabel("time / s")
        ax.axhline(summary["settings"]["time_limit_s"], color="red", lw=0.8, ls="--")
    fig.suptitle(f"{world}: task times per configuration (dashed: the 600 s limit)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _success_plot(plt: Any, summary: dict[str, Any], world: str, path: Path) -> None:
    cells = summary["tasks"][world]
    configs = list(cells)
    fig, ax = plt.subplots(figsize=(8, 3.2))
    width = 0.8 / len(configs)
    for k, c in enumerate(configs):
        rates = [100 * (cells[c][t]["success_rate"] or 0.0) for t in TASKS]
        ax.bar(np.arange(4) + k * width, rates, width, label=c)
    ax.set_xticks(np.arange(4) + 0.4 - width / 2, [_TASK_NAMES[t] for t in TASKS])
    ax.set_ylabel("success / %")
    ax.set_ylim(0, 105)
    ax.legend(ncol=len(configs), fontsize=8, loc="lower right")
    ax.set_title(f"{world}: success rate per task and configuration")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _heatmap_plot(plt: Any, result: BenchResult, world: str, path: Path) -> bool:
    maps = result.heatmaps.get(world, {})
    if not maps:
        return False
    nav = result.navs[world]
    fig, axes = plt.subplots(1, len(maps), figsize=(5 * len(maps), 3.6), squeeze=False)
    g = nav.grid
    extent = (g.origin_xy_m[0], g.origin_xy_m[0] + g.shape[1] * g.resolution_m,
              g.origin_xy_m[1], g.origin_xy_m[1] + g.shape[0] * g.resolution_m)
    for ax, (name, hm) in zip(axes[0], maps.items(), strict=True):
        ax.imshow(np.where(nav.free, 1.0, 0.35), origin="lower", cmap="gray", vmin=0, vmax=1, extent=extent)
        heat = np.ma.masked_less(hm.heat, 0.02)
        ax.imshow(heat, origin="lower", cmap="inferno", alpha=0.8, vmin=0, vmax=0.8, extent=extent)
        idle = nav.idle_position()
        ax.plot(*idle, "c^", ms=8, label="idle position")
        bottles = [o.box.center_m for o in nav.world.objects if o.class_name == "bottle"]
        if bottles:
            b = np.asarray(bottles)
            ax.plot(b[:, 0], b[:, 1], "g.", ms=6, label="true bottles")
        ax.set_title(f"{name} heatmap ({hm.rows} rows, {hm.instances} instances)", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True


def _fmt(v: Any, digits: int = 3) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.{digits}f}"
    if isinstance(v, list | tuple):
        return "; ".join(_fmt(x, digits) for x in v)
    return str(v)


def _task_table(summary: dict[str, Any], world: str) -> list[str]:
    cells = summary["tasks"][world]
    lines = ["| config | " + " | ".join(f"{_TASK_NAMES[t]}: median s (success)" for t in TASKS) + " |",
             "|---|" + "---|" * 4]
    for c, row in cells.items():
        parts = [f"{_fmt(row[t]['median_time_s'], 1)} ({row[t]['successes']}/{row[t]['runs']})"
                 for t in TASKS]
        lines.append(f"| {c} | " + " | ".join(parts) + " |")
    lines += ["", "Why runs ended: " + "; ".join(
        f"{c} {t}: " + ", ".join(f"{k} {v}" for k, v in summary["reasons"][world][c][t].items())
        for c in cells for t in TASKS if any(k not in ("found", "grasped", "arrived")
                                              for k in summary["reasons"][world][c][t]))]
    return lines


def _table3(summary: dict[str, Any], world: str) -> list[str]:
    from hiper_cli.evaluate.foreground import PAPER_TABLE_III

    t3 = summary["perception"][world]["table3"]
    configs = list(t3)
    rows = [("3D detect. time / s: μ; σ", "detect_time_s", "detect_time_s"),
            ("Classification i: TP", "tp", None), ("Classification i: FP", "fp", None),
            ("FP share", "fp_share", "fp_share"), ("Sum i", "sum_i", None), ("Sum o", "sum_o", None),
            ("Loc. accuracy / m: μ; σ", "localisation_classified_m", "localisation_m"),
            ("People dyn. ratio", "people_dynamic_ratio", "people_dynamic_ratio"),
            ("People |v| / m/s: μ; σ", "people_speed_mps", "people_speed_mps"),
            ("People CI / m/s", "people_speed_ci_mps", "people_speed_ci_mps"),
            ("Points per frame after background", "points_after_background_mean", None)]
    lines = ["| row | " + " | ".join(configs) + " | paper |", "|---|" + "---|" * (len(configs) + 1)]
    for label, key, paper_key in rows:
        paper = PAPER_TABLE_III.get(paper_key, {}).get(world) if paper_key else None
        if key in ("tp", "fp"):
            paper = PAPER_TABLE_III["classification_tp_fp"][world][0 if key == "tp" else 1]
        ours = " | ".join(_fmt(t3[c].get(key)) for c in configs)
        lines.append(f"| {label} | {ours} | {_fmt(paper)} |")
    return lines


def _table2(summary: dict[str, Any], world: str) -> list[str]:
    t2 = summary["perception"][world]["table2"]
    if t2 is None:
        return ["(no configuration with background recognition ran)"]
    paper = t2["paper"] or {}
    lines = ["| row | ours (C1-C3) | paper |", "|---|---|---|"]
    for k, v in t2["ours"].items():
        lines.append(f"| {k} | {_fmt(v)} | {_fmt(paper.get(k))} |")
    return lines


def write_report(result: BenchResult, summary: dict[str, Any], out: Path, command: str) -> Path:
    """Write ``out/report.md`` and its PNGs; returns the Markdown path."""
    plt = require_matplotlib()
    out.mkdir(parents=True, exist_ok=True)
    s = summary["settings"]
    md = [
        "# hiper bench: the ablation study (C1-C5) on tasks T1-T4", "",
        f"Worlds {', '.join(s['worlds'])}; configurations {', '.join(s['configs'])}; {s['runs']} runs per "
        f"task, configuration and world; logs of {s['log_s']:.0f} s ({s['mapping_s']:.0f} s mapping) at "
        f"{s['rate_hz']:g} Hz, {s['width_px']}x{s['height_px']} px; time limit "
        f"{s['time_limit_s']:.0f} s.", "",
        "Reproduce:", "", "```", command, "```", "",
        f"World seeds: {s['world_seeds']}. Run seeds (people's start and warm-up, detector luck; the same "
        f"for every configuration): {s['run_seeds']}.", "",
        "Wall time / s: " + ", ".join(f"{k} {v}" for k, v in summary["seconds"].items()), "",
        "## C3 (no heatmaps) against C1: change of the mean task time", "",
        "| task | " + " | ".join(s["worlds"]) + " |", "|---|" + "---|" * len(s["worlds"]),
    ]
    for task, per in summary["c3_vs_c1"].items():
        cells = [f"ours {_fmt(per[w]['ours'], 2)}, paper {_fmt(per[w]['paper'], 2)}" for w in s["worlds"]]
        md.append(f"| {task} | " + " | ".join(cells) + " |")
    for world in s["worlds"]:
        md += ["", f"## {world}", ""]
        _times_plot(plt, summary, world, out / f"times_{world}.png")
        _success_plot(plt, summary, world, out / f"success_{world}.png")
        md += [f"![task times {world}](times_{world}.png)", "",
               f"![success {world}](success_{world}.png)", ""]
        if _heatmap_plot(plt, result, world, out / f"heatmaps_{world}.png"):
            md += [f"![heatmaps {world}](heatmaps_{world}.png)", ""]
        md += _task_table(summary, world)
        md += ["", "T3 workspace (share of runs whose workspace held the bottle's support; movers near the "
               "bottle at the grasp; planning time; the estimate's error):", "",
               "| config | support known | movers near (mean) | movers tracked | plan / s | error / m |",
               "|---|---|---|---|---|---|"]
        for c, v in summary["t3"][world].items():
            md.append(f"| {c} | {_fmt(v['support_known'], 2)} | {_fmt(v['movers_near_mean'], 2)} | "
                      f"{_fmt(v['movers_tracked'])} | {_fmt(v['plan_s'], 2)} | {_fmt(v['error_m_median'])} |")
        md += ["", "T4 carry back:", "",
               "| config | path / m | waited / s | close encounters (steps < 0.5 m) |",
               "|---|---|---|---|"]
        for c, v in summary["t4"][world].items():
            md.append(f"| {c} | {_fmt(v['path_m_mean'], 1)} | {_fmt(v['waited_s_mean'], 1)} | "
                      f"{_fmt(v['close_encounters_mean'], 1)} |")
        md += ["", f"### Table II ({world}, background on the mapping phase)", "", *_table2(summary, world)]
        md += ["", f"### Table III ({world}, per configuration)", "", *_table3(summary, world)]
    path = out / "report.md"
    path.write_text("\n".join(md) + "\n", encoding="utf-8")
    return path
