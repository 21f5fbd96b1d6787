"""``hiper sim`` as a function: one log, or several sessions of one place with changes between."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from hiper_cli.sim.writer import SimConfig

__all__ = ["run_sim"]


def run_sim(out: str | Path, config: SimConfig | None = None, *, world: str = "house", seconds: float = 60.0,
            seed: int = 0, sessions: int = 1, changes: int = 0, overwrite: bool = False,
            progress: Callable[[int, int], None] | None = None) -> dict[str, Any]:
    """Write ``seconds`` of ``world`` to ``out`` (``simulate``), or with several ``sessions`` or
    any ``changes`` the sessions of one place (``simulate_sessions``). Returns the result's dict."""
    from hiper_cli.sim.sessions import simulate_sessions
    from hiper_cli.sim.writer import simulate

    if sessions > 1 or changes:
        return simulate_sessions(world, sessions, changes, seconds, seed, out, config, overwrite=overwrite,
                                 progress=progress).to_dict()
    return simulate(world, seconds, seed, out, config, overwrite=overwrite, progress=progress).to_dict()
