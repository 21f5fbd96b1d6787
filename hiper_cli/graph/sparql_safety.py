"""Read-only SPARQL, decided on the parsed query, and a time limit on running it.

``readonly_form`` parses the text with rdflib's SPARQL grammar (nothing is evaluated, no store
is touched) and walks the parse tree: an update, or a ``SERVICE`` pattern anywhere (however it
is spelled: ``SERVICE<...>``, a prefixed name, a variable, comments or ``\\u`` escapes in
between), is refused before the query reaches pyoxigraph, whose evaluator would fetch the
remote endpoint. ``run_with_timeout`` evaluates in a worker thread (pyoxigraph releases the GIL)
and gives up after ``timeout_s`` with a ``QueryError``.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, TypeVar

from hiper_cli.errors import QueryError

__all__ = ["DEFAULT_TIMEOUT_S", "readonly_form", "run_with_timeout"]

DEFAULT_TIMEOUT_S = 30.0
_FORMS = {"SelectQuery": "SELECT", "AskQuery": "ASK", "ConstructQuery": "CONSTRUCT",
          "DescribeQuery": "DESCRIBE"}
T = TypeVar("T")
# rdflib's pyparsing grammar is not thread-safe (packrat cache, lazy module set-up): a threaded
# server parses one query at a time (each takes milliseconds; evaluation stays parallel)
_PARSING = threading.Lock()


def readonly_form(sparql: str, prefixes: str = "") -> str:
    """The form (SELECT, ASK, CONSTRUCT, DESCRIBE) of a read-only query; ``QueryError`` for an
    update, a federated ``SERVICE`` call or text that does not parse."""
    from pyparsing import ParseBaseException
    from rdflib.plugins.sparql.parser import parseQuery, parseUpdate

    text = prefixes + sparql
    with _PARSING:
        try:
            tree = parseQuery(text)
        except (ParseBaseException, RecursionError, ValueError, TypeError) as err:
            try:
                parseUpdate(text)
            except (ParseBaseException, RecursionError, ValueError, TypeError):
                raise QueryError(f"SPARQL query does not parse: {_one_line(err)}") from None
            raise QueryError("SPARQL update refused: the scene graph is read-only here; send a SELECT, "
                             "ASK, CONSTRUCT or DESCRIBE query") from None
        try:
            service = _has_service(tree)
        except RecursionError:
            raise QueryError("SPARQL query nested too deeply") from None
    if service:
        raise QueryError("SPARQL SERVICE (federated query) refused: only this knowledge base is queried")
    return _FORMS.get(getattr(tree[1], "name", ""), "SELECT")


def _has_service(node: Any) -> bool:
    from rdflib.plugins.sparql.parserutils import CompValue

    if isinstance(node, CompValue):
        return node.name == "ServiceGraphPattern" or any(_has_service(v) for v in node.values())
    if isinstance(node, list | tuple) or type(node).__name__ == "ParseResults":
        return any(_has_service(v) for v in node)
    return False


def _one_line(err: BaseException) -> str:
    return " ".join(str(err).split())[:300] or type(err).__name__


def run_with_timeout(work: Callable[[], T], timeout_s: float | None) -> T:
    """``work()`` in a daemon thread, its result or its exception; ``QueryError`` once
    ``timeout_s`` pass (the evaluation is abandoned: pyoxigraph cannot be interrupted, so the
    thread ends with its query or with the process). None: no limit."""
    if timeout_s is None:
        return work()
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["value"] = work()
        except BaseException as err:  # handed to the caller's thread
            box["error"] = err

    worker = threading.Thread(target=target, name="sparql-query", daemon=True)
    worker.start()
    worker.join(timeout_s)
    if worker.is_alive():
        raise QueryError(f"SPARQL query ran past its time limit of {timeout_s:g} s; add a LIMIT or more "
                         "specific patterns, or raise --timeout")
    if "error" in box:
        raise box["error"]
    value: T = box["value"]
    return value
