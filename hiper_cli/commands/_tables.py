"""How the commands show their results to people: one ``show_*`` per result, rich tables.

Each takes the result's ``to_dict()`` form, the same data ``--json`` prints, so what a person
reads and what a machine reads cannot drift apart.
"""

from __future__ import annotations

from typing import Any

__all__ = ["show_log_info", "show_perceive"]


def show_perceive(out: Any, data: dict[str, Any]) -> None:
    """A ``perceive`` summary: frames, rate, stages not run, skipped frames, counts per class."""
    from rich.table import Table

    out.print(
        f"[bold]{data['frames_read']}[/] frames read, {data['frames_skipped']} skipped, "
        f"{data['frames_per_s']:.2f} frames/s -> {data['kb']} (environment {data['environment']!r}, "
        f"session {data['session_id']})"
    )
    for name, why in data["unavailable_stages"].items():
        out.print(f"[yellow]stage {name} not run:[/] {why}")
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {item['source']}: {item['reason']}")
    table = Table("layer", "class", "observations", "instances")
    layers = sorted(set(data["observations"]) | set(data["instances"]))
    for layer in layers:
        classes = sorted(set(data["observations"].get(layer, {})) | set(data["instances"].get(layer, {})))
        for cls in classes:
            table.add_row(layer, cls, str(data["observations"].get(layer, {}).get(cls, 0)),
                          str(data["instances"].get(layer, {}).get(cls, 0)))
    out.print(table)


def show_log_info(out: Any, data: dict[str, Any]) -> None:
    """A log summary (``hiper info``): frames, rate, camera, pose source, gaps, skipped frames."""
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


