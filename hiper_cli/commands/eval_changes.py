"""``hiper eval changes``: change detection, re-identification and ghosts over several sessions."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._common import DEFAULT_KB, JSON_OPTION, KbOption
from hiper_cli.commands._render import console, print_json
from hiper_cli.commands.eval import eval_app


@eval_app.command("changes")
def changes(
    truth: Annotated[Path, typer.Argument(help="The folder 'hiper sim --sessions N --changes K' wrote.")],
    kb: KbOption = DEFAULT_KB,
    json_out: bool = JSON_OPTION,
) -> None:
    """Change precision / recall / F1 per kind, re-identification precision, ghost rate, count
    error per class and alignment error, of a knowledge base its sessions were perceived into.

    Example: hiper sim --sessions 3 --changes 6 -o days && for s in 1 2 3; do hiper perceive
    days/session_$s --kb days.hiper --detector truth; done && hiper eval changes days --kb days.hiper
    """
    from hiper_cli.evaluate import evaluate_changes

    report = evaluate_changes(kb, truth).to_dict()
    if json_out:
        print_json(report)
        return
    _show(report)


def _show(r: dict[str, Any]) -> None:
    from rich.table import Table

    out = console()
    kinds = Table("change", "stored", "true", "matched", "precision", "recall", "F1")
    for kind, v in r["per_kind"].items():
        kinds.add_row(kind, str(v["stored"]), str(v["true"]), str(v["matched"]), f"{v['precision']:.2f}",
                      f"{v['recall']:.2f}", f"{v['f1']:.2f}")
    out.print(kinds)
    reid = "n/a" if r["reid_precision"] is None else f"{r['reid_precision']:.2f}"
    ghost = "n/a" if r["ghost_rate"] is None else f"{r['ghost_rate']:.2f}"
    out.print(f"re-identification precision {reid} ({r['reid_merged']} instances over sessions); ghost rate "
              f"{ghost} ({r['ghosts']} of {r['present_real']} present objects)")
    for a in r["alignment"]:
        out.print(f"session {a['session']} ({a['log']}): {a['method']}, fitness {a['fitness']:.2f}, error "
                  f"{a['error_m']:.3f} m / {a['error_deg']:.2f} deg")
    counts = Table("class", "stored", "true", "error")
    for cls, v in r["counts"].items():
        counts.add_row(cls, str(v["stored"]), str(v["true"]), f"{v['error']:+d}")
    out.print(counts)


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
