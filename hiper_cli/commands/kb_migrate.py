"""``hiper kb migrate``: carry a knowledge base of an older schema version forward."""

from __future__ import annotations

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands.kb import kb_app
from hiper_cli.render import console, print_json

__all__ = ["register"]


@kb_app.command("migrate")
def migrate_command(kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None,
                    as_json: bool = JSON_OPTION) -> None:
    """Migrate a knowledge base written by an older hiper to this one's schema, after a backup copy.

    Example: hiper kb migrate --kb house.hiper
    """
    from hiper_cli.graph import migrate_kb

    report = migrate_kb(kb, docs_dir=kb_docs)
    if as_json:
        print_json(report.to_dict())
    elif report.migrated:
        console().print(f"{report.kb}: schema version {report.from_version} -> {report.to_version}; "
                        f"the old base is kept in {report.backup}")
    else:
        console().print(f"{report.kb}: schema version {report.to_version}, nothing to migrate")


def register(app: object) -> None:
    """Nothing to do: the command adds itself to ``hiper kb`` on import."""
