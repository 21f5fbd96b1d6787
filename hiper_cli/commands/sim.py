"""``hiper sim``: write a synthetic RGB-D log with ground truth (library: ``hiper_cli.sim.simulate``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import HiperTyper, console, frame_progress, print_json, safe_text

HELP = (
    "Simulate a robot driving through a house, hospital or office: a TUM RGB-D log (rgb, depth, poses) "
    "plus ground truth in OUT/gt (instances, people tracks, per-pixel ids, noisy truth detections). A "
    "mapping phase without people comes first. --sensor records it as a real camera and pose "
    "source would (structured-light by default; ideal gives the exact render).\n\n"
    "Example: hiper sim --world hospital --seconds 60 --seed 1 -o out/hospital\n\n"
    "Several sessions of one place with changes between them: hiper sim --sessions 3 --changes 6 -o out/days"
)
Out = Annotated[Path, typer.Option("--out", "-o", help="Output folder (created; must be empty).")]


def sim(
    out: Out,
    world: str = typer.Option("house", "--world", "-w", help="World preset: house, hospital or office."),
    seconds: float = typer.Option(60.0, "--seconds", "-s", help="Length of the log in seconds."),
    seed: int = typer.Option(0, "--seed", help="Seed: the same seed gives identical output."),
    rate_hz: float = typer.Option(30.0, "--rate-hz", help="Frame rate."),
    width: int = typer.Option(640, "--width", help="Image width in pixels."),
    height: int = typer.Option(480, "--height", help="Image height in pixels."),
    max_range_m: float = typer.Option(5.0, "--max-range-m", help="No depth returns beyond this range."),
    mapping_s: float | None = typer.Option(
        None, "--mapping-s", help="Length of the mapping phase (no people); default a third, at most 60 s."),
    speed_mps: float = typer.Option(0.6, "--speed-mps", help="Robot speed (at most 0.9 m/s)."),
    depth_noise: bool = typer.Option(
        True, "--depth-noise/--no-depth-noise", help="Range-dependent depth noise."),
    miss_rate: float = typer.Option(0.1, "--miss-rate", help="Truth detector: chance to miss an object."),
    jitter: float = typer.Option(0.05, "--jitter", help="Truth detector: box jitter, fraction of box size."),
    false_positives: float = typer.Option(
        0.05, "--false-positives", help="Truth detector: random false boxes per image (mean)."),
    confusion: float = typer.Option(0.03, "--confusion", help="Truth detector: chance of a wrong class."),
    png_compression: int = typer.Option(3, "--png-compression", help="PNG compression level 0-9."),
    sensor: str = typer.Option(
        "structured-light", "--sensor", help="Sensor profile: structured-light, tof, stereo or ideal (exact "
        "depth with --depth-noise, exact poses); see docs/sensors.md."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Write into a non-empty output folder."),
    sessions: int = typer.Option(
        1, "--sessions", help="Logs of one place, each in its own odometry frame (OUT/session_K)."),
    changes: int = typer.Option(
        0, "--changes", help="Objects moved, removed or added between sessions (truth: OUT/changes.json)."),
    as_json: bool = JSON_OPTION,
) -> None:
    from hiper_cli.sim import SimConfig, simulate

    config = SimConfig.from_flat(
        rate_hz=rate_hz, mapping_s=mapping_s, width_px=width, height_px=height, max_range_m=max_range_m,
        speed_mps=speed_mps, depth_noise=depth_noise, miss_rate=miss_rate, jitter_frac=jitter,
        false_positives_per_image=false_positives, confusion_rate=confusion, png_compression=png_compression,
        sensor=sensor)
    screen = console()
    if sessions > 1 or changes:
        _sessions(world, sessions, changes, seconds, seed, out, config, overwrite, as_json)
        return
    with frame_progress(f"sim {safe_text(world)}", screen, enabled=not as_json) as bar:
        result = simulate(world, seconds, seed, out, config, overwrite=overwrite,
                          progress=bar.update if bar else None)
    if as_json:
        print_json(result.to_dict())
        return
    screen.print(
        f"[green]wrote[/] {safe_text(result.out)}: {result.frames} frames of {safe_text(result.world)} "
        f"(seed {result.seed}), "
        f"mapping {result.mapping_s:.1f} s then {result.people} people; {result.instances} instances; "
        f"{result.sensor} sensor; "
        f"{result.frames_per_s:.1f} frames/s"
    )


def _sessions(world: str, sessions: int, changes: int, seconds: float, seed: int, out: Path, config: Any,
              overwrite: bool, as_json: bool) -> None:
    """``--sessions N --changes K``: N logs of one place (``hiper_cli.sim.sessions``)."""
    from hiper_cli.sim.sessions import simulate_sessions

    screen = console()
    with frame_progress(f"sim {world} x{sessions}", screen, enabled=not as_json) as bar:
        result = simulate_sessions(world, sessions, changes, seconds, seed, out, config, overwrite=overwrite,
                                   progress=bar.update if bar else None)
    if as_json:
        print_json(result.to_dict())
        return
    kinds = ", ".join(f"{sum(c['kind'] == k for c in result.changes)} {k}"
                      for k in ("moved", "removed", "added"))
    screen.print(f"[green]wrote[/] {result.out}: {sessions} sessions of {world} (seed {seed}) in their own "
                 f"frames; changes: {kinds} (truth: {result.out / 'changes.json'})")


def register(app: HiperTyper) -> None:
    app.command("sim", help=HELP)(sim)
