"""The named SPARQL queries shipped with the package (top-level ``queries/*.rq``, installed
as ``hiper_cli/queries``). They are filled only through variable bindings
(``KnowledgeBase.query_bound``), never by pasting values into their text."""

from __future__ import annotations

from functools import cache
from importlib import resources

from hiper_cli.errors import QueryError

__all__ = ["template", "template_names"]


def template_names() -> list[str]:
    """The names of the shipped queries (file stems)."""
    root = resources.files("hiper_cli").joinpath("queries")
    return sorted(p.name.removesuffix(".rq") for p in root.iterdir() if p.name.endswith(".rq"))


@cache
def template(name: str) -> str:
    """The text of ``queries/NAME.rq``."""
    path = resources.files("hiper_cli").joinpath("queries", f"{name}.rq")
    if not path.is_file():
        raise QueryError(f"no named query {name!r}; expected one of {', '.join(template_names())}")
    return path.read_text(encoding="utf-8")
