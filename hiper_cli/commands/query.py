"""``hiper query "..."`` and ``hiper query --sparql QUERY|FILE`` (library: ``query/request.py``)."""

from __future__ import annotations

from typing import Annotated, Any

import typer
from typer.core import TyperGroup

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, HiperTyper, KbDocsOption, KbOption


class _AskByDefault(TyperGroup):
    """``hiper query WORDS...`` runs ``ask``: the first word that names no subcommand starts a query."""

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        ask = bool(args) and args[0] not in (*self.commands, "--help", "-h")
        return super().parse_args(ctx, ["ask", *args] if ask else args)


query_app = HiperTyper(name="query", cls=_AskByDefault, no_args_is_help=True, add_completion=False, help=(
    "Ask the scene memory in plain words or SPARQL; typed answers as a table or --json.\n\nPlain words: "
    "classes (cups, people, objects), in FOV, closest, within 2 m of me, near the table, on the closest "
    "table, moving/static, last 10 minutes, since 10:00, how many, where, when, how long, is there, go to."
    '\n\nExample: hiper query "cups in FOV" --kb house.hiper --json'))


@query_app.command("ask")
def ask_command(
    words: Annotated[list[str] | None, typer.Argument(help="The query in plain words.")] = None,
    kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None, as_json: bool = JSON_OPTION,
    pose: Annotated[str | None, typer.Option(
        help="Reference pose x,y,z,yaw (m, rad, map frame); default: the robot's last pose.")] = None,
    at: Annotated[str | None, typer.Option(
        help="Ask from the robot's pose at this time (s, HH:MM or ISO).")] = None,
    now: Annotated[str | None, typer.Option(
        help="'now' for relative times (default: --at, else the KB's last stamp).")] = None,
    limit: Annotated[int | None, typer.Option(help="At most this many hits.")] = None,
    sparql: Annotated[str | None, typer.Option(help="Run a read-only SPARQL query instead of plain words: "
                                               "the query itself, a FILE or '-' (stdin).")] = None,
    timeout_s: Annotated[float, typer.Option(
        "--timeout", help="Give up on a --sparql query after this many seconds.")] = 30.0,
) -> None:
    """Answer a plain-words query, or a read-only SPARQL query with --sparql.

    Example: hiper query "where was the bottle last seen" --kb house.hiper
    """
    from hiper_cli.query.request import run_query
    from hiper_cli.query.views import query_view
    from hiper_cli.render.rows import emit_view

    answer = run_query(kb, words, sparql=sparql, kb_docs=kb_docs, pose=pose, at=at, now=now, limit=limit,
                       timeout_s=timeout_s)
    emit_view(answer.to_dict(), query_view(answer), as_json)


def register(app: typer.Typer) -> None:
    app.add_typer(query_app)
