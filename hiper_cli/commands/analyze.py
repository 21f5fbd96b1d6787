"""``hiper analyze features|heatmap|map|bench``: interpret the knowledge base (library:
``hiper_cli.analyze``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from hiper_cli.commands._common import JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands._render import console, group, print_json, safe_text

if TYPE_CHECKING:
    from hiper_cli.analyze import FeatureReport

__all__ = ["analyze_app", "register"]

analyze_app = group(
    "analyze",
    "Learn object features, build the map layer and draw heatmaps from a knowledge base.\n\n"
    "Example: hiper analyze heatmap --class person --kb scene.hiper -o maps",
)

FromOption = Annotated[str | None, typer.Option("--from", help="Window start: seconds or ISO date-time.")]
ToOption = Annotated[str | None, typer.Option("--to", help="Window end: seconds or ISO date-time.")]
LastOption = Annotated[str | None, typer.Option("--last", help="Only the last span of data, e.g. 1h, 15min.")]
DailyOption = Annotated[
    str | None, typer.Option("--daily", help="Only this time of every day (UTC), e.g. 09:00-10:00.")
]
EnvOption = Annotated[str | None, typer.Option("--env", help="Environment (default: the only one).")]


def _window(kb: Any, t_from: str | None, t_to: str | None, last: str | None, daily: str | None) -> Any:
    from hiper_cli.analyze import resolve_window

    return resolve_window(
        t_from=t_from, t_to=t_to, last=last, daily=daily, newest_stamp_s=kb.newest_sighting_s()
    )


def _fmt(v: float | None, digits: int = 3) -> str:
    return "-" if v is None else f"{v:.{digits}f}"


def _print_features(report: FeatureReport) -> None:
    """The features as two tables, each one line per class in an 80-column terminal: the
    Object Dynamic Score, then size and altitude."""
    from rich.markup import escape
    from rich.table import Table

    def narrow(title: str, *names: str) -> Table:
        table = Table(title=title, title_justify="left", box=None, pad_edge=False, padding=(0, 1, 0, 0),
                      header_style="bold underline")
        for name in names:
            table.add_column(escape(name), no_wrap=True)
        return table

    def interval(lo: float | None, hi: float | None) -> str:
        return escape(f"[{_fmt(lo)}, {_fmt(hi)}]")

    ods = narrow(f"object dynamics, {report.window.describe()}", "class", "tracks", "rows", "dynamic",
                 "σ m/s", "μ_v m/s", "μ_v 95 % CI", "[c_l, c_u] m/s")
    shape = narrow(escape("size and altitude (mean [95 % CI])"), "class", "size m³", "altitude m")
    for c in report.classes:
        o = c.ods
        ods.add_row(safe_text(c.class_name), str(o.instances), str(o.rows), f"{100 * o.ratio:.1f} %",
                    _fmt(o.sigma_mps),
                    _fmt(o.mean_mps), interval(o.mean_lo_mps, o.mean_hi_mps), interval(o.cl_mps, o.cu_mps))
        size = f"{_fmt(c.size.mean_m3)} {interval(c.size.lo_m3, c.size.hi_m3)}" if c.size else "-"
        alt = f"{_fmt(c.altitude.mean_m)} {interval(c.altitude.lo_m, c.altitude.hi_m)}" if c.altitude else "-"
        shape.add_row(safe_text(c.class_name), size, alt)
    out = console()
    out.print(ods)
    out.print(shape)


@analyze_app.command("features")
def features_command(
    class_name: Annotated[
        list[str] | None, typer.Option("--class", help="Class (repeatable; default all).")
    ] = None,
    t_from: FromOption = None,
    t_to: ToOption = None,
    last: LastOption = None,
    daily: DailyOption = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", help="Write histograms (paper Fig. 8) to this PNG.")
    ] = None,
    no_store: Annotated[
        bool, typer.Option("--no-store", help="Show the features only; leave the KB as it is.")
    ] = False,
    kb: KbOption = "scene.hiper",
    kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Per class: the Object Dynamic Score [μ_v, c_l, c_u, r] with the 2σ noise split, and box
    size and altitude with 95 % bootstrap intervals; stored as analyses in the map layer, where
    perception reads them as priors.

    Example: hiper analyze features --class person --kb scene.hiper --plot person.png
    """
    from hiper_cli.analyze import learn_features
    from hiper_cli.graph import open_kb

    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        window = _window(knowledge, t_from, t_to, last, daily)
        report, stored = learn_features(knowledge, class_name or None, window, store=not no_store)
    plot_path = None
    if plot is not None:
        from hiper_cli.analyze.plot import plot_features

        plot_path = str(plot_features(report, plot))
    data = report.to_dict() | {"stored": len(stored), "plot": plot_path}
    if as_json:
        print_json(data)
        return
    _print_features(report)
    out = console()
    out.print(
        f"{len(stored)} analyses stored in {safe_text(kb)}"
        + (f"; histograms in {safe_text(plot_path)}" if plot_path else "")
    )


@analyze_app.command("heatmap")
def heatmap_command(
    class_name: Annotated[
        str, typer.Option("--class", help="The class whose whereabouts to draw.")
    ] = "person",
    t_from: FromOption = None,
    t_to: ToOption = None,
    last: LastOption = None,
    daily: DailyOption = None,
    inverse: Annotated[
        bool, typer.Option("--inverse", help="Also write the inverse map (for search).")
    ] = False,
    out_dir: Annotated[Path, typer.Option("--out", "-o", help="Output folder (default: here).")] = Path("."),
    map_yaml: Annotated[
        str | None,
        typer.Option("--map", help="map_server YAML to draw on (stored as the environment's map)."),
    ] = None,
    env: EnvOption = None,
    kb: KbOption = "scene.hiper",
    kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Algorithm 5: the class's trajectories in the window inflated by a normal distribution and
    capped at 80 % occupancy, on the map; writes a PNG and nav2 costmap-filter masks (keepout
    and speed limit, raw PGM + YAML, with the filter servers' parameters and a costmap snippet).

    Example: hiper analyze heatmap --class person --daily 09:00-10:00 --inverse -o maps
    """
    from hiper_cli.analyze import generate_heatmap
    from hiper_cli.graph import open_kb

    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        window = _window(knowledge, t_from, t_to, last, daily)
        result = generate_heatmap(
            knowledge, class_name, window, out_dir, env_name=env, map_yaml=map_yaml, inverse=inverse
        )
    data = result.to_dict()
    if as_json:
        print_json(data)
        return
    out = console()
    out.print(
        f"[bold]{safe_text(class_name)}[/] heatmap, {result.heatmap.window.describe()}: "
        f"{data['rows']} rows of "
        f"{data['instances']} tracks, σ {data['kernel_sigma_m']:.2f} m (μ_v {data['speed_mps']:.2f} m/s "
        f"from {data['speed_source']}), {data['hot_cells']} hot cells, {data['seconds']:.2f} s"
    )
    for name, path in data["files"].items():
        out.print(f"  {name:16} {safe_text(path)}")


@analyze_app.command("map")
def map_command(
    out: Annotated[
        Path, typer.Option("--out", "-o", help="map_server YAML to write (PGM beside it).")
    ] = Path("map.yaml"),
    map_yaml: Annotated[
        str | None, typer.Option("--map", help="Load this map_server YAML as the environment's map instead.")
    ] = None,
    resolution_m: Annotated[
        float, typer.Option("--resolution-m", help="Cell size when built from the KB.")
    ] = 0.05,
    env: EnvOption = None,
    kb: KbOption = "scene.hiper",
    kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """The map layer: an occupancy grid built from the background and the observed trajectories
    (or loaded with --map), stored in the environment and exported as map_server YAML + PGM.

    Example: hiper analyze map --kb scene.hiper -o maps/floor.yaml
    """
    from hiper_cli.analyze import export_map
    from hiper_cli.graph import open_kb

    with open_kb(kb, docs_dir=kb_docs, create=False) as knowledge:
        data = export_map(knowledge, out, env_name=env, map_yaml=map_yaml, resolution_m=resolution_m)
    if as_json:
        print_json(data)
        return
    console().print(
        f"map {data['shape'][1]}x{data['shape'][0]} cells of {data['resolution_m']} m "
        f"({data['free_cells']} free, {data['occupied_cells']} occupied) "
        f"-> {safe_text(data['yaml'])}"
    )


@analyze_app.command("bench")
def bench_command(
    kb: Annotated[Path, typer.Option("--kb", help="Bench knowledge base (filled on first use).")] = Path(
        "/tmp/hiper-analyze-bench.hiper"
    ),
    hours: Annotated[float, typer.Option("--hours", help="Hours of data when filling it.")] = 2.0,
    as_json: bool = JSON_OPTION,
) -> None:
    """Time features (all classes) and a heatmap on a KB of 2 h of data (>= 1 M observations,
    >= 200 k trajectory rows), each in a fresh process with its peak memory.

    Example: hiper analyze bench --kb /tmp/bench.hiper --json
    """
    from hiper_cli.analyze.bench import run_analyze_bench

    data = run_analyze_bench(kb, hours=hours)
    if as_json:
        print_json(data)
        return
    out = console()
    size = data["kb"]
    out.print(
        f"{safe_text(kb)}: {size['observations']} observations, {size['instances']} instances, "
        f"{size['trajectory_rows']} trajectory rows ({size['fill_s']:.0f} s to fill)"
    )
    out.print(f"  column cache brought up to date: {data['cache']['seconds']:.2f} s")
    for name in ("features", "heatmap"):
        r = data[name]
        out.print(
            f"  {name:9} {r['seconds']:.3f} s (budget {r['budget_s']} s; warm {r['warm_s']:.3f} s), "
            f"peak RSS {r['peak_rss_mb']:.0f} MB"
        )


def register(app: typer.Typer) -> None:
    app.add_typer(analyze_app, name="analyze")
