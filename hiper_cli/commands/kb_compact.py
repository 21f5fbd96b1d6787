"""``hiper kb compact``: summarise what adds nothing (``graph.maintain.compact_kb``)."""

from __future__ import annotations

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Json, Kb, keep_duration_s
from hiper_cli.cmdline import kb as o
from hiper_cli.render import emit
from hiper_cli.render.kb import show_compact

__all__ = ["register"]


@o.kb_app.command("compact")
def compact_command(kb: Kb = DEFAULT_KB, keep_observations: o.KeepObservations = "0",
                    as_json: Json = False) -> None:
    """Summarise the observations that add nothing and drop debris; fused objects, change
    events and movers' trajectories stay, and queries answer the same.

    Example: hiper kb compact --kb scene.hiper --keep-observations '1 h'
    """
    from hiper_cli.graph.maintain import compact_kb
    emit(compact_kb(kb, keep_duration_s(keep_observations)), as_json, lambda out, d: show_compact(out, d, kb))


def register(app: HiperTyper) -> None:
    """Nothing to do: the command adds itself to ``hiper kb`` on import."""
