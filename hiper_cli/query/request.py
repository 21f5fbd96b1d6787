"""A query as a person types it: plain words or SPARQL, with the pose and times as text.

``hiper query`` and any front end that takes text (a web form, a chat tool) call these, so the
options are read and checked one way: ``run_query`` (either, by the knowledge base's location),
``ask_words`` (the grammar of ``grammar.py``), ``workspace_at`` (a box of the map),
``ask_sparql`` (read-only SPARQL over all graphs), ``sparql_source`` (the query itself, a file
or stdin), ``parse_floats`` and ``parse_stamp`` for coordinates and times.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from hiper_cli.errors import QueryError
from hiper_cli.graph.kb import KnowledgeBase, open_kb_for_reading
from hiper_cli.query.results import Answer

__all__ = ["MAX_COORDINATE_M", "SparqlAnswer", "ask_sparql", "ask_words", "parse_floats", "parse_stamp",
           "run_query", "sparql_source", "workspace_at"]

MAX_COORDINATE_M = 1e6  # a pose further out is a typo, not a place in a map
# the first word of a SPARQL query given inline rather than as a file
SPARQL_OPENINGS = ("select", "ask", "construct", "describe", "prefix", "base", "insert", "delete", "with",
                   "load", "clear", "drop", "create", "copy", "move", "add")


def parse_floats(text: str | None, n: int, option: str, form: str) -> tuple[float, ...] | None:
    """``n`` comma-separated finite numbers (None stays None); a ``QueryError`` names ``option``."""
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != n or not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE_M for v in values):
        raise QueryError(f"{option} {text!r}: expected {n} comma-separated finite numbers {form}, "
                         f"each at most {MAX_COORDINATE_M:g} in size")
    return values


def parse_stamp(text: str | None, option: str, now_s: float) -> float | None:
    """A time: seconds (a stamp), HH:MM on the day of ``now_s``, or an ISO date-time."""
    if text is None:
        return None
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


def ask_words(kb: KnowledgeBase, words: str, *, pose: str | None = None, at: str | None = None,
              now: str | None = None, limit: int | None = None) -> Answer:
    """A plain-words query with the reference pose ``x,y,z,yaw`` and the times as text (times
    of day fall on the day of the knowledge base's last stamp)."""
    if not words.strip():
        raise QueryError('no query; e.g. hiper query "cups in FOV" or --sparql "SELECT ..."')
    from hiper_cli.query.ask import ask

    span = kb.stamp_span()
    last = span[1] if span else 0.0
    reference = parse_floats(pose, 4, "--pose", "x,y,z,yaw (m, m, m, rad)")
    return ask(kb, words, pose=reference, at_s=parse_stamp(at, "--at", last),  # type: ignore[arg-type]
               now_s=parse_stamp(now, "--now", last), limit=limit)


@dataclass(frozen=True)
class SparqlAnswer:
    """A SPARQL answer: ``form`` (SELECT, ASK, CONSTRUCT, DESCRIBE), its media type and body."""

    form: str
    media_type: str
    body: bytes

    @property
    def is_graph(self) -> bool:
        return self.form in ("CONSTRUCT", "DESCRIBE")

    def to_dict(self) -> dict[str, Any]:
        """SPARQL JSON results; a graph as its media type and Turtle text."""
        if self.is_graph:
            return {"media_type": self.media_type, "text": self.body.decode("utf-8", "replace")}
        data: dict[str, Any] = json.loads(self.body)
        return data


def ask_sparql(kb: KnowledgeBase, text: str, timeout_s: float | None = 30.0) -> SparqlAnswer:
    """Any read-only SPARQL query over all graphs (updates and ``SERVICE`` refused)."""
    from hiper_cli.graph.sparql_safety import readonly_form

    form = readonly_form(text)
    media = "text/turtle" if form in ("CONSTRUCT", "DESCRIBE") else "application/sparql-results+json"
    body, media = kb.run_readonly(text, media, timeout_s=timeout_s)
    return SparqlAnswer(form, media, body)


def sparql_source(value: str, stdin: IO[str]) -> str:
    """The query ``--sparql VALUE`` names: '-' reads ``stdin``; text that opens like a SPARQL
    query and names no file is the query; anything else is a file to read. Checked read-only
    before any knowledge base is opened."""
    from hiper_cli.graph.sparql_safety import readonly_form

    if value == "-":
        text = stdin.read()
    elif value.startswith("--"):  # hiper query "SELECT ..." --sparql --kb x.hiper
        raise QueryError(f"--sparql {value}: expected the query, a FILE or '-' right after --sparql")
    elif _opens_like_sparql(value):
        text = value
    else:
        try:
            text = Path(value).read_text(encoding="utf-8")
        except OSError as err:
            raise QueryError(f"{value}: cannot read the SPARQL file ({err.strerror}); pass the query itself "
                             "(--sparql 'SELECT ...'), a .rq file or '-'") from err
    readonly_form(text)
    return text


def _opens_like_sparql(value: str) -> bool:
    """Text that opens like a SPARQL query and names no file is a query given inline."""
    words = value.split(maxsplit=1)
    return len(words) > 1 and words[0].lower() in SPARQL_OPENINGS and not _is_file(value)


def _is_file(value: str) -> bool:
    try:
        return Path(value).is_file()
    except OSError:  # a long query is no file name (ENAMETOOLONG)
        return False


def run_query(kb: str | Path, words: Sequence[str] | None = None, *, sparql: str | None = None,
              kb_docs: str | Path | None = None, pose: str | None = None, at: str | None = None,
              now: str | None = None, limit: int | None = None, timeout_s: float | None = 30.0,
              stdin: IO[str] | None = None) -> Answer | SparqlAnswer:
    """``hiper query`` in one call: plain ``words`` or the query ``sparql`` names (``sparql_source``;
    checked before the knowledge base at ``kb`` is opened for reading), answered."""
    text = None if sparql is None else sparql_source(sparql, stdin or sys.stdin)
    if text is not None and words:
        raise QueryError(f"--sparql with plain words too ({' '.join(words)!r}); ask one or the other")
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        if text is not None:
            return ask_sparql(knowledge, text, timeout_s)
        return ask_words(knowledge, " ".join(words or ()), pose=pose, at=at, now=now, limit=limit)


def workspace_at(kb: str | Path, center: str, size: str, *, resolution_m: float = 0.05,
                 kb_docs: str | Path | None = None) -> Any:
    """``hiper query workspace`` in one call: the ``Workspace`` of the box centred at ``center``
    (x,y,z m) with edge ``size`` (m, or sx,sy,sz) in the knowledge base at ``kb``."""
    from hiper_cli.query.workspace import workspace

    c = parse_floats(center, 3, "--center", "x,y,z (m)")
    n, form = (3, "sx,sy,sz (m)") if "," in size else (1, "(m)")
    s = parse_floats(size, n, "--size", form)
    assert c is not None and s is not None
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        return workspace(knowledge, c, s if len(s) == 3 else s[0], resolution_m=resolution_m)  # type: ignore[arg-type]
