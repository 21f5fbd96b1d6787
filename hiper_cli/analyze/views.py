"""What a person reads of an analysis: headlines and tables of plain strings.

No terminal codes here: the CLI prints a ``TextTable`` with rich (escaping what the knowledge
base holds); ``--json`` prints the results' ``to_dict`` instead. The query layer's answers use
the same ``TextTable`` (``query/views.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from hiper_cli.analyze.features import FeatureReport

__all__ = ["TextTable", "bench_lines", "feature_tables", "heatmap_lines", "map_line"]


@dataclass(frozen=True)
class TextTable:
    """A headline, then ``rows`` under ``headers`` (none: the headline alone). ``compact``: one
    line per row in an 80-column terminal, no rules, no column wraps but those in ``wrap``."""

    headline: str
    headers: list[str]
    rows: list[list[str]] = field(default_factory=list)
    compact: bool = False
    wrap: tuple[str, ...] = ()


def _fmt(v: float | None, digits: int = 3) -> str:
    return "-" if v is None else f"{v:.{digits}f}"


def _interval(lo: float | None, hi: float | None) -> str:
    return f"[{_fmt(lo)}, {_fmt(hi)}]"


def feature_tables(report: FeatureReport) -> list[TextTable]:
    """The Object Dynamic Score per class, then size and altitude per class."""
    ods, shape = [], []
    for c in report.classes:
        o = c.ods
        ods.append([c.class_name, str(o.instances), str(o.rows), f"{100 * o.ratio:.1f} %", _fmt(o.sigma_mps),
                    _fmt(o.mean_mps), _interval(o.mean_lo_mps, o.mean_hi_mps), _interval(o.cl_mps, o.cu_mps)])
        size = f"{_fmt(c.size.mean_m3)} {_interval(c.size.lo_m3, c.size.hi_m3)}" if c.size else "-"
        a = c.altitude
        alt = f"{_fmt(a.mean_m)} {_interval(a.lo_m, a.hi_m)}" if a else "-"
        shape.append([c.class_name, size, alt])
    return [
        TextTable(f"object dynamics, {report.window.describe()}",
                  ["class", "tracks", "rows", "dynamic", "σ m/s", "μ_v m/s", "μ_v 95 % CI", "[c_l, c_u] m/s"],
                  ods, compact=True),
        TextTable("size and altitude (mean [95 % CI])", ["class", "size m³", "altitude m"], shape,
                  compact=True),
    ]


def heatmap_lines(data: dict[str, Any], class_name: str, window: str) -> list[str]:
    """A ``HeatmapResult.to_dict``: what went into it, then the files written."""
    head = (f"{class_name} heatmap, {window}: {data['rows']} rows of {data['instances']} tracks, σ "
            f"{data['kernel_sigma_m']:.2f} m (μ_v {data['speed_mps']:.2f} m/s from {data['speed_source']}), "
            f"{data['hot_cells']} hot cells, {data['seconds']:.2f} s")
    return [head] + [f"  {name:16} {path}" for name, path in data["files"].items()]


def map_line(data: dict[str, Any]) -> str:
    """An ``export_map`` summary in one line."""
    return (f"map {data['shape'][1]}x{data['shape'][0]} cells of {data['resolution_m']} m "
            f"({data['free_cells']} free, {data['occupied_cells']} occupied) -> {data['yaml']}")


def bench_lines(data: dict[str, Any], kb: str) -> list[str]:
    """A ``run_analyze_bench`` report: the knowledge base, then each timing with its budget."""
    size = data["kb"]
    lines = [f"{kb}: {size['observations']} observations, {size['instances']} instances, "
             f"{size['trajectory_rows']} trajectory rows ({size['fill_s']:.0f} s to fill)",
             f"  column cache brought up to date: {data['cache']['seconds']:.2f} s"]
    for name in ("features", "heatmap"):
        r = data[name]
        lines.append(f"  {name:9} {r['seconds']:.3f} s (budget {r['budget_s']} s; warm {r['warm_s']:.3f} s), "
                     f"peak RSS {r['peak_rss_mb']:.0f} MB")
    return lines
