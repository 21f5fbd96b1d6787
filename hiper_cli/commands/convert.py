"""``hiper convert LOG OUT --to FORMAT``: rewrite a sensor log as TUM, rosbag1, rosbag2 or MCAP.

``--degrade PROFILE`` writes it instead as a TUM folder seen by a real sensor (``hiper_cli.sensor``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from hiper_cli.cmdline import HiperTyper, Json, Log, with_log_flags
from hiper_cli.cmdline import convert as o
from hiper_cli.render import console, emit, frame_progress, safe_text
from hiper_cli.render.perceive import show_converted

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions


def convert(log: Log, out: o.Out, to: o.To = None, rgb_format: o.RgbFormat = "raw",
            depth_encoding: o.DepthEncoding = "16UC1", pose_as: o.PoseAs = "tf",
            overwrite: o.Overwrite = False, degrade: o.Degrade = None, seed: o.Seed = 0,
            pose_drift: o.PoseDrift = None, json_out: Json = False, *, log_options: LogOptions) -> None:
    from hiper_cli.sensor.convert import rewrite_log

    label = f"writing {safe_text(out)}" if degrade is None else f"degrading to {safe_text(out)}"
    with frame_progress(label, console(), enabled=not json_out, late=True) as bar:
        data = rewrite_log(log, out, log_options, to=to, rgb_format=rgb_format, depth_encoding=depth_encoding,
                           pose_as=pose_as, degrade=degrade, seed=seed, pose_drift=pose_drift,
                           overwrite=overwrite, on_start=bar.start if bar else None,
                           on_frame=bar.advance if bar else None)
    emit(data, json_out, show_converted)


def register(app: HiperTyper) -> None:
    app.command(name="convert", help=o.HELP)(with_log_flags(convert))
