"""``hiper sim``: write a synthetic RGB-D log with ground truth (library: ``hiper_cli.sim.run``)."""

from __future__ import annotations

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.cmdline import sim as o
from hiper_cli.render import console, emit, frame_progress, safe_text
from hiper_cli.render.sim import show_sim


def sim(out: o.Out, world: o.World = "house", seconds: o.Seconds = 60.0, seed: o.Seed = 0,
        rate_hz: o.RateHz = 30.0, width: o.Width = 640, height: o.Height = 480,
        max_range_m: o.MaxRangeM = 5.0, mapping_s: o.MappingS = None, speed_mps: o.SpeedMps = 0.6,
        depth_noise: o.DepthNoise = True, miss_rate: o.MissRate = 0.1, jitter: o.Jitter = 0.05,
        false_positives: o.FalsePositives = 0.05, confusion: o.Confusion = 0.03,
        png_compression: o.PngCompression = 3, sensor: o.Sensor = "structured-light",
        overwrite: o.Overwrite = False, sessions: o.Sessions = 1, changes: o.Changes = 0,
        as_json: Json = False) -> None:
    from hiper_cli.sim import SimConfig
    from hiper_cli.sim.run import run_sim

    config = SimConfig.from_flat(
        rate_hz=rate_hz, mapping_s=mapping_s, width_px=width, height_px=height, max_range_m=max_range_m,
        speed_mps=speed_mps, depth_noise=depth_noise, miss_rate=miss_rate, jitter_frac=jitter,
        false_positives_per_image=false_positives, confusion_rate=confusion, png_compression=png_compression,
        sensor=sensor)
    label = f"sim {world} x{sessions}" if sessions > 1 or changes else f"sim {safe_text(world)}"
    with frame_progress(label, console(), enabled=not as_json) as bar:
        data = run_sim(out, config, world=world, seconds=seconds, seed=seed, sessions=sessions,
                       changes=changes, overwrite=overwrite, progress=bar.update if bar else None)
    emit(data, as_json, lambda screen, d: show_sim(screen, d, world, seed))


def register(app: HiperTyper) -> None:
    app.command("sim", help=o.HELP)(sim)
