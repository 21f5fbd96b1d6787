"""The analyses as a person asks for them: a knowledge base by location, a window as text.

``hiper analyze features|heatmap|map`` call these (the MCP tools call ``learn_features`` and
``generate_heatmap`` with an open knowledge base); each opens the knowledge base, reads the
window options against its newest data, runs the analysis and returns its result, whose
``to_dict`` is the ``--json`` form and whose ``view`` is what a person reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.analyze.features import FeatureReport, learn_features
from hiper_cli.analyze.generate import HeatmapResult, generate_heatmap
from hiper_cli.analyze.maplayer import export_map
from hiper_cli.analyze.views import TextTable, feature_tables, heatmap_lines, map_line
from hiper_cli.analyze.window import TimeWindow, resolve_window
from hiper_cli.graph.kb import KnowledgeBase, open_kb

__all__ = ["FeaturesRun", "HeatmapRun", "MapRun", "WindowText", "features_at", "heatmap_at", "map_at",
           "window_of"]


@dataclass(frozen=True)
class WindowText:
    """``--from``/``--to`` (seconds or ISO), ``--last`` (e.g. 1h) and ``--daily`` (HH:MM-HH:MM)."""

    t_from: str | None = None
    t_to: str | None = None
    last: str | None = None
    daily: str | None = None


def window_of(kb: KnowledgeBase, text: WindowText) -> TimeWindow:
    """The window ``text`` describes; ``--last`` counts back from the newest foreground sighting."""
    return resolve_window(t_from=text.t_from, t_to=text.t_to, last=text.last, daily=text.daily,
                          newest_stamp_s=kb.newest_sighting_s())


@dataclass(frozen=True)
class FeaturesRun:
    report: FeatureReport
    stored: int
    kb: str
    plot: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return self.report.to_dict() | {"stored": self.stored, "plot": self.plot}

    def view(self) -> list[TextTable | str]:
        done = f"{self.stored} analyses stored in {self.kb}" + (
            f"; histograms in {self.plot}" if self.plot else "")
        return [*feature_tables(self.report), done]


def features_at(kb: str | Path, class_names: list[str] | None = None, window: WindowText | None = None,
                *, kb_docs: str | Path | None = None, plot: Path | None = None,
                store: bool = True) -> FeaturesRun:
    """``hiper analyze features`` in one call: learn (and ``store``) the features of
    ``class_names`` (default all) in the window; ``plot``: histograms to this PNG."""
    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        span = window_of(knowledge, window or WindowText())
        report, stored = learn_features(knowledge, class_names or None, span, store=store)
    plot_path = None
    if plot is not None:
        from hiper_cli.analyze.plot import plot_features

        plot_path = str(plot_features(report, plot))
    return FeaturesRun(report, len(stored), str(kb), plot_path)


@dataclass(frozen=True)
class HeatmapRun:
    result: HeatmapResult
    class_name: str

    def to_dict(self) -> dict[str, Any]:
        return self.result.to_dict()

    def view(self) -> list[str]:
        return heatmap_lines(self.to_dict(), self.class_name, self.result.heatmap.window.describe())


def heatmap_at(kb: str | Path, class_name: str = "person", window: WindowText | None = None,
               out_dir: str | Path = ".", *, kb_docs: str | Path | None = None, env_name: str | None = None,
               map_yaml: str | None = None, inverse: bool = False) -> HeatmapRun:
    """``hiper analyze heatmap`` in one call: the heatmap of ``class_name`` in the window, its
    PNG and costmap masks in ``out_dir``."""
    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        span = window_of(knowledge, window or WindowText())
        result = generate_heatmap(knowledge, class_name, span, out_dir, env_name=env_name, map_yaml=map_yaml,
                                  inverse=inverse)
    return HeatmapRun(result, class_name)


@dataclass(frozen=True)
class MapRun:
    summary: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return self.summary

    def view(self) -> list[str]:
        return [map_line(self.summary)]


def map_at(kb: str | Path, out_yaml: str | Path = "map.yaml", *, kb_docs: str | Path | None = None,
           env_name: str | None = None, map_yaml: str | None = None, resolution_m: float = 0.05) -> MapRun:
    """``hiper analyze map`` in one call: the environment's map stored and written as map_server
    YAML + PGM."""
    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        return MapRun(export_map(knowledge, out_yaml, env_name=env_name, map_yaml=map_yaml,
                                 resolution_m=resolution_m))
