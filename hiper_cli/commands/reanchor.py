"""``hiper reanchor``: recompute the background instances of a knowledge base with new poses.

Library: ``hiper_cli.reanchor.reanchor_kb`` (beside ``hiper_cli.pipeline``: it reruns the
background recomputation over what a knowledge base holds).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._render import JSON_OPTION, HiperTyper, console, print_json
from hiper_cli.commands.perceive import KB_DOCS_HELP, KB_HELP


def register(app: HiperTyper) -> None:
    @app.command(
        "reanchor",
        help=(
            "Recompute every background instance (walls, floors, ceilings, tables) of a knowledge "
            "base from its observations with an optimised trajectory, e.g. after a loop closure. "
            "Each observation takes the pose at its stamp in the TUM trajectory; instances the new "
            "poses bring together are merged. Written in one transaction.\n\n"
            "Example: hiper reanchor --kb house.hiper --poses optimised.txt"
        ),
    )
    def reanchor_command(
        poses: Annotated[Path, typer.Option("--poses", help="TUM trajectory (stamp tx ty tz qx qy qz qw).")],
        kb: Annotated[str, typer.Option("--kb", help=KB_HELP)] = "scene.hiper",
        kb_docs: Annotated[Path | None, typer.Option("--kb-docs", help=KB_DOCS_HELP)] = None,
        max_dt_s: Annotated[
            float, typer.Option("--max-dt-s", help="Hold the end poses this long beyond the trajectory.")
        ] = 0.05,
        dry_run: Annotated[
            bool, typer.Option("--dry-run", help="Compute and report; write nothing.")
        ] = False,
        json_out: bool = JSON_OPTION,
    ) -> None:
        from hiper_cli.graph import open_kb
        from hiper_cli.perceive.logs import read_tum_trajectory
        from hiper_cli.reanchor import reanchor_kb

        trajectory = read_tum_trajectory(poses)
        with open_kb(kb, docs_dir=kb_docs) as knowledge:
            summary: dict[str, Any] = reanchor_kb(knowledge, trajectory, max_dt_s=max_dt_s, write=not dry_run)
        summary["kb"] = str(kb)
        summary["poses"] = str(poses)
        if json_out:
            print_json(summary)
            return
        console().print(
            f"[bold]{kb}[/]: {summary['instances']} background instances recomputed from "
            f"{summary['observations']} observations; {summary['merged']} merged away; mean shift "
            f"{summary['shift_mean_m']:.3f} m (max {summary['shift_max_m']:.3f} m)"
            + (" [dim](dry run: nothing written)[/]" if dry_run else "")
        )
