"""What a person reads of a query's answer: a headline and a table of plain strings.

No terminal codes here: the CLI prints a ``TextTable`` (``analyze/views.py``) with rich, escaping
what the knowledge base holds; ``--json`` prints the answer's ``to_dict`` instead.
"""

from __future__ import annotations

from typing import Any

from hiper_cli.analyze.views import TextTable
from hiper_cli.query.request import SparqlAnswer
from hiper_cli.query.results import Answer, ago_text, short_uuid

__all__ = ["TextTable", "answer_table", "bench_view", "query_view", "sparql_table", "workspace_view"]


def query_view(answer: Answer | SparqlAnswer) -> TextTable | str:
    """What ``run_query`` answered: a table, or the Turtle text of a CONSTRUCT or DESCRIBE."""
    if isinstance(answer, Answer):
        return answer_table(answer)
    data = answer.to_dict()
    return str(data["text"]) if answer.is_graph else sparql_table(data)


def answer_table(answer: Answer) -> TextTable:
    """The answer's text, then one line per hit in an 80-column terminal."""
    headers = ["class", "uuid", "position m", "dist m", "seen", "state", "m/s", "on", "obs"]
    rows = []
    for h in answer.hits:
        x, y, z = h.center_map_m
        rows.append([h.class_name, short_uuid(h.uuid), f"{x:.2f} {y:.2f} {z:.2f}", f"{h.distance_m:.2f}",
                     ago_text(h.last_seen_s, answer.now_s), h.state,
                     "" if h.speed_mps is None else f"{h.speed_mps:.2f}",
                     "" if h.support is None else h.support.class_name, str(h.observation_count)])
    return TextTable(answer.text, headers if rows else [], rows, compact=True, wrap=("on",))


def sparql_table(data: dict[str, Any]) -> TextTable:
    """SPARQL JSON results: ASK as yes/no, SELECT as a table of the bound values."""
    if "boolean" in data:
        return TextTable("yes" if data["boolean"] else "no", [])
    names = list(data["head"]["vars"])
    rows = [[row[n]["value"] if n in row else "" for n in names] for row in data["results"]["bindings"]]
    return TextTable("", names, rows)


def workspace_view(ws: Any) -> TextTable:
    """A ``Workspace``: its box and what it holds, one line per shape or class."""
    occupied = int((ws.occupancy >= 0).sum())
    headline = (f"workspace {ws.size_m} m at {ws.center_m}: {len(ws.background)} background shapes, "
                f"{len(ws.foreground_uuids)} objects, {occupied} of {ws.occupancy.size} voxels occupied")
    rows = [["background", p.class_name, p.shape, ""] for p in ws.background]
    rows += [["foreground", name, str(int((ws.occupancy == k).sum())), str(ws.dynamics[name])]
             for k, name in enumerate(ws.classes)]
    return TextTable(headline, ["layer", "class", "shape / voxels", "dynamics"], rows)


def bench_view(report: dict[str, Any]) -> TextTable:
    """``run_query_bench``'s report: sizes and the cold start, then p50/p95 per query form."""
    cold = report["cold"]
    headline = (f"{report['counts']} (built in {report['build_s']} s); first query of a process reads the "
                f"instance index: {cold['index_wall_ms']} ms ({cold['index_cpu_ms']} ms CPU); load average "
                f"{report['load_average'][0]:.1f}")
    rows = [[name, f"{p['p50_ms']:.1f}", f"{p['p95_ms']:.1f}", f"{p['max_ms']:.1f}", f"{p['cpu_p95_ms']:.1f}"]
            for name, p in report["forms"].items()]
    return TextTable(headline, ["query form", "p50 ms", "p95 ms", "max ms", "p95 CPU ms"], rows)
