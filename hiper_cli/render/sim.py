"""What ``hiper sim`` shows: the log written, or the sessions and their changes."""

from __future__ import annotations

from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_sim"]


def show_sim(out: Any, data: dict[str, Any], world: str, seed: int) -> None:
    """One line: frames, world, phases, instances, sensor, rate; or sessions and changes."""
    if "sessions" in data:
        kinds = ", ".join(f"{sum(c['kind'] == k for c in data['changes'])} {k}"
                          for k in ("moved", "removed", "added"))
        out.print(f"[green]wrote[/] {data['out']}: {len(data['sessions'])} sessions of {world} (seed {seed}) "
                  f"in their own frames; changes: {kinds} (truth: {data['out']}/changes.json)")
        return
    out.print(
        f"[green]wrote[/] {safe_text(data['out'])}: {data['frames']} frames of {safe_text(data['world'])} "
        f"(seed {data['seed']}), "
        f"mapping {data['mapping_s']:.1f} s then {data['people']} people; {data['instances']} instances; "
        f"{data['sensor']} sensor; "
        f"{data['frames_per_s']:.1f} frames/s"
    )
