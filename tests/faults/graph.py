"""The scene graph damaged: kb check rebuilds it from the documents, nothing lost."""

from __future__ import annotations

from collections.abc import Callable

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.runner import Workspace


def _damage_graph(how: str) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        inputs.damage_graph(ws.kb, how)

    return prepare


def cases() -> list[Case]:
    cases: list[Case] = []
    for how in ("sst", "current", "manifest", "file"):
        cases.append(Case(f"graph/damaged-{how}-check", "graph", _argv("kb check --kb {kb}"), "ok",
                          "kb check rebuilds the scene graph from the documents",
                          prepare=_damage_graph(how)))
        cases.append(Case(f"graph/damaged-{how}-info", "graph", _argv("kb info --kb {kb}"), "any",
                          "read from the documents or one line: run 'hiper kb check'",
                          prepare=_damage_graph(how), kb="repairable"))
    cases.append(Case("graph/damaged-export", "graph", _argv("export {root}/out.ttl --kb {kb}"), "error",
                      "one line: run 'hiper kb check' to rebuild the graph", prepare=_damage_graph("sst"),
                      kb="repairable"))
    return cases
