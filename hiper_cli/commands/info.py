"""``hiper info LOG``: what a sensor log holds (frames, rate, camera, poses, detections, gaps)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from hiper_cli.commands._log_options import LOG_ARGUMENT, open_log_from_flags, with_log_flags
from hiper_cli.commands._render import JSON_OPTION, console, print_json

HELP = (
    "Show what a sensor log holds: frames, rate, duration, resolution, intrinsics, pose source, "
    "detections and stamp gaps.\n\n"
    "Example: hiper info rgbd_dataset_freiburg1_xyz --poses slam.txt --json"
)


def info(
    log: Path = LOG_ARGUMENT,
    json_out: bool = JSON_OPTION,
    frames: bool = typer.Option(False, "--frames", help="Also list every frame's stamp and pose."),
    check: bool = typer.Option(
        False, "--check", help="Decode every image and report the frames that cannot be read."
    ),
    log_flags: dict[str, Any] | None = None,
) -> None:
    reader = open_log_from_flags(log, **(log_flags or {}))
    summary = reader.info()
    data = summary.to_dict(frames=frames)
    if check:
        readable = sum(1 for _ in reader)
        data["readable_frames"] = readable
        data["skipped"] = [{"source": s, "reason": r} for s, r in reader.skipped]
    if json_out:
        print_json(data)
        return
    _render(data)


def _render(data: dict[str, Any]) -> None:
    from rich.table import Table

    cam = data["camera"]
    table = Table(title=f"{data['path']} ({data['format']})", show_header=False)
    table.add_column("what", style="bold")
    table.add_column("value")
    rows = [
        ("frames", str(data["frames"])),
        ("rate", f"{data['rate_hz']:.3f} Hz"),
        ("duration", f"{data['duration_s']:.3f} s"),
        ("stamps", f"{data['first_stamp_s']:.6f} .. {data['last_stamp_s']:.6f}"),
        ("resolution", f"{cam['width']}×{cam['height']}"),
        ("intrinsics", f"fx {cam['fx']:.2f} fy {cam['fy']:.2f} cx {cam['cx']:.2f} cy {cam['cy']:.2f} "
                       f"depth scale {cam['depth_scale']:g}"
                       + (f" distortion {cam['distortion']}" if cam.get("distortion") else "")),
        ("pose source", data["pose_source"]),
        ("detections", "yes" if data["has_detections"] else "no"),
        ("stamp gaps", ", ".join(f"{g['gap_s']:.3f} s after {g['after_stamp_s']:.3f}"
                                 for g in data["stamp_gaps"][:5])
         + (f" (+{len(data['stamp_gaps']) - 5} more)" if len(data["stamp_gaps"]) > 5 else "") or "none"),
    ]
    rows += [(f"source: {role}", where) for role, where in data["sources"].items()]
    if "readable_frames" in data:
        rows.append(("readable", f"{data['readable_frames']} of {data['frames']}"))
    rows.append(("skipped", str(len(data["skipped"]))))
    for name, value in rows:
        table.add_row(name, value)
    out = console()
    out.print(table)
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {item['source']}: {item['reason']}")
    if len(data["skipped"]) > 10:
        out.print(f"[yellow]... {len(data['skipped']) - 10} more skipped[/]")
    if data.get("frame_list"):
        frames = Table(title="frames")
        for column in ("pose_id", "stamp_s", "x y z qx qy qz qw"):
            frames.add_column(column)
        for item in data["frame_list"]:
            frames.add_row(str(item["pose_id"]), f"{item['stamp_s']:.6f}",
                           " ".join(f"{v:.4f}" for v in item["pose_xyz_qxyzw"]))
        out.print(frames)


def register(app: typer.Typer) -> None:
    app.command(name="info", help=HELP)(with_log_flags(info))
