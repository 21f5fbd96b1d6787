"""``hiper kb info|check|sessions|bench``: look after a knowledge base."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands._render import console, group, print_json

__all__ = ["kb_app", "register"]

kb_app = group(
    "kb",
    "Inspect, check and benchmark a knowledge base.\n\nExample: hiper kb info --kb scene.hiper",
)


@kb_app.command("info")
def info_command(
    kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None, as_json: bool = JSON_OPTION
) -> None:
    """Counts per layer and class, environments, sessions and size on disk.

    Example: hiper kb info --kb scene.hiper --json
    """
    from hiper_cli.graph import open_kb_for_reading

    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        data = knowledge.info()
    if as_json:
        print_json(data)
        return
    from hiper_cli.commands._tables import show_kb_info

    show_kb_info(console(), data)


@kb_app.command("check")
def check_command(
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    no_repair: Annotated[
        bool, typer.Option("--no-repair", help="Only report; do not rebuild the graph.")
    ] = False,
    as_json: bool = JSON_OPTION,
) -> None:
    """Verify the documents and that the scene graph agrees with them; rebuild the graph if not.

    Exit code 1 when the knowledge base is (still) inconsistent.

    Example: hiper kb check --kb scene.hiper
    """
    from hiper_cli.graph import open_kb

    # open without the automatic catch-up so the check sees what a crash left behind; a graph
    # that cannot be opened is rebuilt from the documents (unless --no-repair)
    with open_kb(kb, docs_dir=kb_docs, sync=False, create=False, read_only=no_repair,
                 rebuild_damaged_graph=not no_repair) as knowledge:
        report = knowledge.check(repair=not no_repair)
    if as_json:
        print_json(report.to_dict())
    else:
        from hiper_cli.commands._tables import show_kb_check

        show_kb_check(console(), report.to_dict())
    if not report.ok:
        raise typer.Exit(1)


@kb_app.command("sessions")
def sessions_command(
    kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None, as_json: bool = JSON_OPTION
) -> None:
    """The sessions of the knowledge base: id, place, log, log stamps, when it ran, alignment.

    Example: hiper kb sessions --kb scene.hiper --json
    """
    from hiper_cli.graph import open_kb_for_reading

    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        rows = knowledge.session_records()
    if as_json:
        print_json({"kb": kb, "sessions": rows})
        return
    from hiper_cli.commands._tables import show_sessions

    show_sessions(console(), rows)


@kb_app.command("compact")
def compact_command(
    kb: KbOption = DEFAULT_KB,
    keep_observations: Annotated[str, typer.Option(
        "--keep-observations", help="Keep raw observations this long before the newest stamp "
        "('10 minutes', '2 h'; default 0: summarise all that add nothing).")] = "0",
    as_json: bool = JSON_OPTION,
) -> None:
    """Summarise the observations that add nothing and drop debris; fused objects, change
    events and movers' trajectories stay, and queries answer the same.

    Example: hiper kb compact --kb scene.hiper --keep-observations '1 h'
    """
    from hiper_cli.commands.perceive import keep_duration_s
    from hiper_cli.graph import open_kb
    from hiper_cli.graph.compact import compact

    keep_s = keep_duration_s(keep_observations)
    with open_kb(kb, create=False) as knowledge:
        report = compact(knowledge, keep_raw_s=keep_s or 0.0).to_dict()
    if as_json:
        print_json(report)
        return
    console().print(
        f"[green]compacted[/] {kb}: {report['observations_before']} -> {report['observations_after']} "
        f"observations ({report['summarised']} summarised, {report['debris_dropped']} debris), "
        f"{report['bytes_before'] / 1e6:.2f} -> {report['bytes_after'] / 1e6:.2f} MB of documents in "
        f"{report['seconds']:.1f} s")


def register(app: typer.Typer) -> None:
    app.add_typer(kb_app, name="kb")
