"""``hiper query "..."``, ``hiper query --sparql QUERY|FILE``, ``hiper query workspace``,
``hiper query bench``: ask the scene memory (see docs/query.md)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from typer.core import TyperGroup

from hiper_cli.commands._common import DEFAULT_KB, KbDocsOption, KbOption
from hiper_cli.commands._render import JSON_OPTION, HiperTyper, console, print_json, safe_text
from hiper_cli.errors import QueryError

__all__ = ["query_app", "register"]


class _AskByDefault(TyperGroup):
    """``hiper query WORDS...`` runs the ``ask`` subcommand: the first word that is no
    subcommand name starts a plain-words query."""

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        if args and args[0] not in self.commands and args[0] not in ("--help", "-h"):
            args = ["ask", *args]
        return super().parse_args(ctx, args)


query_app = HiperTyper(
    name="query",
    cls=_AskByDefault,
    no_args_is_help=True,
    add_completion=False,
    help=(
        "Ask the scene memory in plain words or SPARQL; typed answers as a table or --json.\n\n"
        "Plain words: classes (cups, people, objects), in FOV, closest, within 2 m of me, near the "
        "table, on the closest table, moving/static, last 10 minutes, since 10:00, how many, where, "
        "when, how long, is there, go to.\n\n"
        'Example: hiper query "cups in FOV" --kb house.hiper --json'
    ),
)



def _floats(text: str | None, n: int, option: str, form: str) -> tuple[float, ...] | None:
    if text is None:
        return None
    import math

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != n or not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE_M for v in values):
        raise QueryError(f"{option} {text!r}: expected {n} comma-separated finite numbers {form}, "
                         f"each at most {MAX_COORDINATE_M:g} in size")
    return values


def _stamp(text: str | None, option: str, now_s: float) -> float | None:
    """A time option: seconds (a stamp), HH:MM on the day of the KB's last stamp, or ISO."""
    if text is None:
        return None
    import math

    try:
        stamp_s = float(text)
    except ValueError:
        pass
    else:
        if not math.isfinite(stamp_s) or abs(stamp_s) > 1e11:
            raise QueryError(f"{option} {text!r}: expected a finite stamp in seconds (at most 1e11), "
                             "HH:MM or an ISO date-time")
        return stamp_s
    from hiper_cli.query.grammar import parse_time

    stamp = parse_time(text, now_s)
    if stamp is None:
        raise QueryError(f"{option} {text!r}: expected a stamp in seconds, HH:MM or an ISO date-time")
    return stamp


MAX_COORDINATE_M = 1e6  # a pose further out is a typo, not a place in a map


@query_app.command("ask")
def ask_command(
    words: Annotated[list[str] | None, typer.Argument(help="The query in plain words.")] = None,
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    pose: Annotated[
        str | None,
        typer.Option(
            "--pose", help="Reference pose x,y,z,yaw (m, rad, map frame); default: the robot's last pose."
        ),
    ] = None,
    at: Annotated[
        str | None, typer.Option("--at", help="Ask from the robot's pose at this time (s, HH:MM or ISO).")
    ] = None,
    now: Annotated[
        str | None,
        typer.Option("--now", help="'now' for relative times (default: --at, else the KB's last stamp)."),
    ] = None,
    limit: Annotated[int | None, typer.Option("--limit", help="At most this many hits.")] = None,
    sparql: Annotated[
        str | None,
        typer.Option(
            "--sparql",
            help="Run a read-only SPARQL query instead of plain words: the query itself, a FILE or "
            "'-' (stdin).",
        ),
    ] = None,
    timeout_s: Annotated[
        float, typer.Option("--timeout", help="Give up on a --sparql query after this many seconds.")
    ] = 30.0,
    as_json: bool = JSON_OPTION,
) -> None:
    """Answer a plain-words query, or a read-only SPARQL query with --sparql.

    Example: hiper query "where was the bottle last seen" --kb house.hiper
    """
    from hiper_cli.graph import open_kb_for_reading

    text = None if sparql is None else sys.stdin.read() if sparql == "-" else _sparql_text(sparql)
    if text is not None and words:
        raise QueryError(f"--sparql with plain words too ({' '.join(words)!r}); ask one or the other")
    if text is not None:
        from hiper_cli.graph.sparql_safety import readonly_form

        form = readonly_form(text)  # refused before the knowledge base is opened
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        if text is not None:
            graph_form = form in ("CONSTRUCT", "DESCRIBE")
            media = "text/turtle" if graph_form else "application/sparql-results+json"
            body = knowledge.run_readonly(text, media, timeout_s=timeout_s)[0]
            (_print_triples if graph_form else _print_sparql)(body, as_json)
            return
        if not words:
            raise QueryError('no query; e.g. hiper query "cups in FOV" or --sparql "SELECT ..."')
        from hiper_cli.query import ask

        span = knowledge.stamp_span()
        last = span[1] if span else 0.0
        answer = ask(
            knowledge,
            " ".join(words),
            pose=_floats(pose, 4, "--pose", "x,y,z,yaw (m, m, m, rad)"),  # type: ignore[arg-type]
            at_s=_stamp(at, "--at", last),
            now_s=_stamp(now, "--now", last),
            limit=limit,
        )
    if as_json:
        print_json(answer.to_dict())
        return
    _render_answer(answer)


# the first word of a SPARQL query given inline rather than as a file
SPARQL_OPENINGS = ("select", "ask", "construct", "describe", "prefix", "base", "insert", "delete", "with",
                   "load", "clear", "drop", "create", "copy", "move", "add")


def _sparql_text(value: str) -> str:
    """The query ``--sparql`` names: its own text when it opens like a SPARQL query and names no
    file, else the file's contents."""
    if value.startswith("--"):  # hiper query "SELECT ..." --sparql --kb x.hiper
        raise QueryError(f"--sparql {value}: expected the query, a FILE or '-' right after --sparql")
    words = value.split(maxsplit=1)
    if len(words) > 1 and words[0].lower() in SPARQL_OPENINGS and not _is_file(value):
        return value
    path = Path(value)
    try:
        return path.read_text(encoding="utf-8")
    except OSError as err:
        raise QueryError(
            f"{path}: cannot read the SPARQL file ({err.strerror}); pass the query itself "
            "(--sparql 'SELECT ...'), a .rq file or '-'"
        ) from err


def _is_file(value: str) -> bool:
    try:
        return Path(value).is_file()
    except OSError:  # a long query is no file name (ENAMETOOLONG)
        return False


def _print_triples(body: bytes, as_json: bool) -> None:
    """A CONSTRUCT or DESCRIBE answer: Turtle text (``--json``: its media type and text)."""
    text = body.decode("utf-8", "replace")
    if as_json:
        print_json({"media_type": "text/turtle", "text": text})
        return
    sys.stdout.write(safe_text(text, markup=False))
    if text and not text.endswith("\n"):
        sys.stdout.write("\n")


def _print_sparql(body: bytes, as_json: bool) -> None:
    import json

    data = json.loads(body)
    if as_json:
        print_json(data)
        return
    out = console()
    if "boolean" in data:
        out.print("yes" if data["boolean"] else "no")
        return
    from rich.table import Table

    names = data["head"]["vars"]
    table = Table(*(safe_text(n) for n in names))
    for row in data["results"]["bindings"]:
        table.add_row(*(safe_text(row[n]["value"]) if n in row else "" for n in names))
    out.print(table)


def _render_answer(answer: Any) -> None:
    from rich.table import Table

    from hiper_cli.query.results import ago_text, short_uuid

    out = console()
    out.print(f"[bold]{safe_text(answer.text)}[/]")
    if not answer.hits:
        return
    # one line per hit in an 80-column terminal: no rules, one space between columns, only the
    # support may be cut
    table = Table(box=None, pad_edge=False, padding=(0, 1, 0, 0), header_style="bold underline")
    for name in ("class", "uuid", "position m", "dist m", "seen", "state", "m/s", "on", "obs"):
        table.add_column(name, no_wrap=name != "on")
    for h in answer.hits:
        x, y, z = h.center_map_m
        table.add_row(
            safe_text(h.class_name),
            short_uuid(h.uuid),
            f"{x:.2f} {y:.2f} {z:.2f}",
            f"{h.distance_m:.2f}",
            ago_text(h.last_seen_s, answer.now_s),
            safe_text(h.state),
            "" if h.speed_mps is None else f"{h.speed_mps:.2f}",
            "" if h.support is None else safe_text(h.support.class_name),
            str(h.observation_count),
        )
    out.print(table)


@query_app.command("workspace")
def workspace_command(
    center: Annotated[str, typer.Option("--center", help="Centre x,y,z of the workspace box (m, map).")],
    size: Annotated[str, typer.Option("--size", help="Edge of the box (m), or sx,sy,sz.")] = "1.0",
    resolution: Annotated[float, typer.Option("--resolution", help="Voxel edge (m).")] = 0.05,
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """What a box of the map holds, for a manipulation planner.

    The static background as primitive shapes with their class, the foreground as a voxel
    grid with classes and learned dynamics (ODS where hiper analyze has run).

    Example: hiper query workspace --center 1.7,1.9,0.8 --size 1.0 --kb house.hiper --json
    """
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.query.workspace import workspace

    c = _floats(center, 3, "--center", "x,y,z (m)")
    s = _floats(size, 3, "--size", "sx,sy,sz (m)") if "," in size else _floats(size, 1, "--size", "(m)")
    assert c is not None and s is not None
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        ws = workspace(knowledge, c, s if len(s) == 3 else s[0], resolution_m=resolution)  # type: ignore[arg-type]
    if as_json:
        print_json(ws.to_dict())
        return
    from rich.table import Table

    out = console()
    occupied = int((ws.occupancy >= 0).sum())
    out.print(
        f"[bold]workspace[/] {ws.size_m} m at {ws.center_m}: {len(ws.background)} background shapes, "
        f"{len(ws.foreground_uuids)} objects, {occupied} of {ws.occupancy.size} voxels occupied"
    )
    table = Table("layer", "class", "shape / voxels", "dynamics")
    for p in ws.background:
        table.add_row("background", safe_text(p.class_name), safe_text(p.shape), "")
    for k, name in enumerate(ws.classes):
        table.add_row("foreground", safe_text(name), str(int((ws.occupancy == k).sum())),
                      str(ws.dynamics[name]))
    out.print(table)


@query_app.command("bench")
def bench_command(
    instances: Annotated[int, typer.Option("--instances", help="Synthetic instances.")] = 10_000,
    observations: Annotated[int, typer.Option("--observations", help="Synthetic observations.")] = 1_000_000,
    queries: Annotated[int, typer.Option("--queries", help="Runs per query form.")] = 50,
    kb: Annotated[Path | None, typer.Option("--kb", help="Keep (or reuse) the synthetic KB here.")] = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Time every query form (p50/p95 ms) on a synthetic knowledge base at scale.

    Example: hiper query bench --instances 10000 --observations 1000000 --kb /tmp/qbench.hiper
    """
    from hiper_cli.query.bench import QueryBenchConfig, run_query_bench

    config = QueryBenchConfig(instances=instances, observations=observations, queries=queries)
    report = run_query_bench(config, kb_path=kb)
    if as_json:
        print_json(report)
        return
    from rich.table import Table

    out = console()
    out.print(
        f"[bold]{report['counts']}[/] (built in {report['build_s']} s); first query of a process "
        f"reads the instance index: {report['cold']['index_wall_ms']} ms "
        f"({report['cold']['index_cpu_ms']} ms CPU); load average {report['load_average'][0]:.1f}"
    )
    table = Table("query form", "p50 ms", "p95 ms", "max ms", "p95 CPU ms")
    for name, p in report["forms"].items():
        table.add_row(
            name, f"{p['p50_ms']:.1f}", f"{p['p95_ms']:.1f}", f"{p['max_ms']:.1f}", f"{p['cpu_p95_ms']:.1f}"
        )
    out.print(table)


def register(app: typer.Typer) -> None:
    app.add_typer(query_app)
