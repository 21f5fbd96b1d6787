"""``hiper kb info|check|sessions``: look after a knowledge base (``graph.maintain``)."""

from __future__ import annotations

import typer

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Json, Kb, KbDocs
from hiper_cli.cmdline import kb as o
from hiper_cli.render import emit
from hiper_cli.render.kb import show_kb_check, show_kb_info, show_sessions

__all__ = ["kb_app", "register"]
kb_app = o.kb_app


@kb_app.command("info")
def info_command(kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, as_json: Json = False) -> None:
    """Counts per layer and class, environments, sessions and size on disk.

    Example: hiper kb info --kb scene.hiper --json
    """
    from hiper_cli.graph.maintain import kb_info
    emit(kb_info(kb, kb_docs), as_json, show_kb_info)


@kb_app.command("check")
def check_command(kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, no_repair: o.NoRepair = False,
                  as_json: Json = False) -> None:
    """Verify the documents and that the scene graph agrees with them; rebuild the graph if not.

    Exit code 1 when the knowledge base is (still) inconsistent.

    Example: hiper kb check --kb scene.hiper
    """
    from hiper_cli.graph.maintain import check_kb
    report = check_kb(kb, kb_docs, repair=not no_repair)
    emit(report, as_json, show_kb_check)
    raise typer.Exit(0 if report["ok"] else 1)


@kb_app.command("sessions")
def sessions_command(kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, as_json: Json = False) -> None:
    """The sessions of the knowledge base: id, place, log, log stamps, when it ran, alignment.

    Example: hiper kb sessions --kb scene.hiper --json
    """
    from hiper_cli.graph.maintain import kb_sessions
    emit(kb_sessions(kb, kb_docs), as_json, show_sessions)


def register(app: HiperTyper) -> None:
    app.add_typer(kb_app, name="kb")


# hiper kb compact lives in its own module; imported here so --help lists it before kb bench
from hiper_cli.commands import kb_compact  # noqa: E402, F401
