"""Histograms of the learned features, like the paper's Figure 8: per class, the speeds (with
the 2σ threshold and the dynamic range), the box volumes and the altitudes (with their 95 %
ranges and the bootstrap CI of the mean).

matplotlib is the optional extra ``hiper[plot]`` (imported here only, when a plot is asked
for): it is ~40 MB of install that perception and the knowledge base never need; the heatmap
PNG is drawn with OpenCV, already a dependency.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hiper_cli.analyze.features import ClassFeatures, FeatureReport
from hiper_cli.errors import ConfigError

__all__ = ["plot_features"]


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError as err:
        raise ConfigError(
            "--plot needs matplotlib: pip install 'hiper[plot]' (or pip install matplotlib)"
        ) from err
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _panel(
    ax: Any,
    values: Any,
    title: str,
    unit: str,
    marks: dict[str, tuple[float, str]],
    span: tuple[float, float] | None,
) -> None:
    ax.hist(values, bins=40, color="#4c72b0", alpha=0.85)
    if span is not None:
        ax.axvspan(span[0], span[1], color="#dd8452", alpha=0.2, label="95 % range")
    for label, (x, style) in marks.items():
        ax.axvline(x, color="k", linestyle=style, linewidth=1.2, label=label)
    ax.set_title(title)
    ax.set_xlabel(unit)
    ax.set_ylabel("count")
    ax.legend(fontsize=7)


def _row(axes: Sequence[Any], c: ClassFeatures) -> None:
    ods = c.ods
    marks = {f"2σ = {ods.threshold_mps:.3f}": (ods.threshold_mps, ":")}
    if ods.mean_mps is not None:
        marks[f"μ_v = {ods.mean_mps:.3f}"] = (ods.mean_mps, "-")
    span = (ods.cl_mps, ods.cu_mps) if ods.cl_mps is not None and ods.cu_mps is not None else None
    _panel(
        axes[0],
        c.speeds_mps,
        f"{c.class_name}: speed (dynamic {100 * ods.ratio:.0f} %)",
        "|v| / m/s",
        marks,
        span,
    )
    if c.size is not None:
        s = c.size
        _panel(
            axes[1],
            c.volumes_m3,
            f"{c.class_name}: box volume (n = {s.instances})",
            "volume / m³",
            {f"mean = {s.mean_m3:.3f}": (s.mean_m3, "-")},
            (s.lo_m3, s.hi_m3),
        )
    if c.altitude is not None:
        a = c.altitude
        _panel(
            axes[2],
            c.altitudes_m,
            f"{c.class_name}: altitude of the box bottom",
            "height above floor / m",
            {f"mean = {a.mean_m:.3f}": (a.mean_m, "-")},
            (a.lo_m, a.hi_m),
        )


def plot_features(report: FeatureReport, out: str | Path) -> Path:
    """Write the histograms of every class in ``report`` to the PNG ``out``; returns its path."""
    if not report.classes:
        raise ConfigError("--plot: no class has data in this window; widen --from/--to")
    plt = _pyplot()
    n = len(report.classes)
    fig, axes = plt.subplots(n, 3, figsize=(13, 3.2 * n), squeeze=False)
    for row, c in zip(axes, report.classes, strict=True):
        _row(row, c)
    fig.suptitle(f"learned features, {report.window.describe()}")
    fig.tight_layout()
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
