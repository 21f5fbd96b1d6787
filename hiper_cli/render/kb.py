"""What ``hiper kb``, ``export`` and ``import`` show: totals, sessions, checks, bench sizes."""

from __future__ import annotations

from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_bench_size", "show_compact", "show_export", "show_import", "show_kb_check", "show_kb_info",
           "show_sessions"]


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


def show_sessions(out: Any, data: dict[str, Any]) -> None:
    """``hiper kb sessions``: one row per session, with its log stamps and alignment."""
    rows = data["sessions"]
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


def show_compact(out: Any, report: dict[str, Any], kb: str) -> None:
    """``hiper kb compact`` of ``kb``: observations and bytes before and after."""
    out.print(
        f"[green]compacted[/] {safe_text(kb)}: {report['observations_before']} -> "
        f"{report['observations_after']} observations ({report['summarised']} summarised, "
        f"{report['debris_dropped']} debris), {report['bytes_before'] / 1e6:.2f} -> "
        f"{report['bytes_after'] / 1e6:.2f} MB of documents in {report['seconds']:.1f} s")


def show_export(out: Any, summary: dict[str, Any]) -> None:
    """``hiper export``: the file written and its format."""
    out.print(f"wrote {safe_text(summary['path'])} ({safe_text(summary['format'])})")


def _plural(kind: str, n: int) -> str:
    """"1 environment", "13 instances", "2 analyses"."""
    if n == 1:
        return kind
    return kind[:-2] + "es" if kind.endswith("is") else kind + "s"


def show_import(out: Any, summary: dict[str, Any]) -> None:
    """``hiper import``: the documents imported, per type."""
    counts = ", ".join(f"{n} {_plural(k, n)}" for k, n in summary["counts"].items())
    out.print(f"imported {counts} into {safe_text(summary['kb'])}")
