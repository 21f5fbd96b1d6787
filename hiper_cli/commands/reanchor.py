"""``hiper reanchor``: recompute the background instances of a knowledge base with new poses.

Library: ``hiper_cli.reanchor.reanchor_with_poses`` (beside ``hiper_cli.pipeline``: it reruns
the background recomputation over what a knowledge base holds).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, HiperTyper, KbDocsOption, KbOption
from hiper_cli.render import console, print_json, safe_text

HELP = (
    "Recompute every background instance (walls, floors, ceilings, tables) of a knowledge base from its "
    "observations with an optimised trajectory, e.g. after a loop closure. Each observation takes the pose "
    "at its stamp in the TUM trajectory; instances the new poses bring together are merged. Written in one "
    "transaction.\n\nExample: hiper reanchor --kb house.hiper --poses optimised.txt"
)
Poses = Annotated[Path, typer.Option("--poses", help="TUM trajectory (stamp tx ty tz qx qy qz qw).")]
MaxDt = Annotated[float, typer.Option(
    "--max-dt-s", "--max-dt", help="Hold the end poses this long beyond the trajectory.")]
DryRun = Annotated[bool, typer.Option("--dry-run", help="Compute and report; write nothing.")]


def reanchor_command(poses: Poses, kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None,
                     max_dt_s: MaxDt = 0.05, dry_run: DryRun = False, json_out: bool = JSON_OPTION) -> None:
    from hiper_cli.reanchor import reanchor_with_poses

    summary = reanchor_with_poses(kb, poses, kb_docs=kb_docs, max_dt_s=max_dt_s, write=not dry_run)
    if json_out:
        print_json(summary.to_dict())
        return
    console().print(
        f"[bold]{safe_text(kb)}[/]: {summary.instances} background instances recomputed from "
        f"{summary.observations} "
        f"observations; {summary.merged} merged away; mean shift {summary.shift_mean_m:.3f} m (max "
        f"{summary.shift_max_m:.3f} m)" + (" [dim](dry run: nothing written)[/]" if dry_run else ""))


def register(app: HiperTyper) -> None:
    app.command("reanchor", help=HELP)(reanchor_command)
