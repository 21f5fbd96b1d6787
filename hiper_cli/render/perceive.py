"""What ``hiper perceive`` and ``hiper info`` show: a run's summary, step costs, a log."""

from __future__ import annotations

from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_converted", "show_live", "show_log_info", "show_perceive", "show_replay_start",
           "show_replayed", "show_run", "show_steps"]


def _skip(item: dict[str, Any]) -> str:
    return f"{safe_text(item['source'])}: {safe_text(item['reason'])}"


def show_perceive(out: Any, data: dict[str, Any]) -> None:
    """A ``perceive`` summary: frames, rate, stages not run, skipped frames, counts per class."""
    from rich.table import Table

    out.print(
        f"[bold]{data['frames_read']}[/] frames read, {data['frames_skipped']} skipped, "
        f"{data['frames_per_s']:.2f} frames/s -> {safe_text(data['kb'])} "
        f"(environment {safe_text(repr(data['environment']))}, "
        f"session {data['session_id']})"
    )
    align = data.get("alignment")
    if align and align["method"] == "registration":
        out.print(f"aligned to the place's map: fitness {align['fitness']:.2f}, rmse {align['rmse_m']:.3f} m"
                  + (f"; {safe_text(align['note'])}" if align.get("note") else ""))
    again = data.get("earlier_sessions", {})
    if any(again.values()):
        out.print(f"earlier sessions' objects: {again['found_again']} found again "
                  f"({again['moved']} moved), {again['vacated']} vacated")
    for name, why in data["unavailable_stages"].items():
        out.print(f"[yellow]stage {safe_text(name)} not run:[/] {safe_text(why)}")
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {_skip(item)}")
    table = Table("layer", "class", "observations", "instances")
    layers = sorted(set(data["observations"]) | set(data["instances"]))
    for layer in layers:
        classes = sorted(set(data["observations"].get(layer, {})) | set(data["instances"].get(layer, {})))
        for cls in classes:
            table.add_row(safe_text(layer), safe_text(cls),
                          str(data["observations"].get(layer, {}).get(cls, 0)),
                          str(data["instances"].get(layer, {}).get(cls, 0)))
    out.print(table)


def show_steps(out: Any, steps: dict[str, dict[str, float]]) -> None:
    """The cost of each step of a ``perceive`` run: mean per frame it ran in, per frame read."""
    from rich.table import Table

    table = Table("step", "frames", "mean ms", "per frame read ms", "total s")
    for name, row in steps.items():
        table.add_row(safe_text(name), str(row["frames"]), f"{row['mean_ms']:.2f}",
                      f"{row['per_frame_ms']:.2f}",
                      f"{row['total_s']:.2f}")
    out.print(table)


def show_run(out: Any, data: dict[str, Any], timings: bool = False) -> None:
    """A ``perceive`` run of a log: the summary, and with ``timings`` the cost of each step."""
    show_perceive(out, data)
    if timings:
        show_steps(out, data["steps"])


def show_live(out: Any, data: dict[str, Any], stats: bool = False) -> None:
    """A live ``perceive`` run: the summary, then what the robot sent and (``stats``) the latency."""
    show_perceive(out, data)
    live = data["live"]
    out.print(f"live: {live['frames_assembled']} frames received, {live['frames_dropped']} dropped to keep "
              f"up, {live['frames_unmatched']} without depth or pose; {len(live['silences'])} silences; "
              f"ended by {live['stopped_by']}")
    if live["bad_messages"]:
        out.print(f"[yellow]{live['bad_messages']} messages could not be read[/] "
                  f"(last: {live['last_error']})")
    if stats:
        lat = live["latency_ms"]
        out.print(f"latency from sending to queryable: p50 {lat['p50']} ms, p95 {lat['p95']} ms, "
                  f"max {lat['max']} ms")


def show_log_info(out: Any, data: dict[str, Any]) -> None:
    """A log summary (``hiper info``): frames, rate, camera, pose source, gaps, skipped frames."""
    from rich.table import Table

    cam = data["camera"]
    title = f"{safe_text(data['path'])} ({safe_text(data['format'])})"
    table = Table(title=title, show_header=False)
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
        ("pose source", safe_text(data["pose_source"])),
        ("detections", "yes" if data["has_detections"] else "no"),
        ("stamp gaps", ", ".join(f"{g['gap_s']:.3f} s after {g['after_stamp_s']:.3f}"
                                 for g in data["stamp_gaps"][:5])
         + (f" (+{len(data['stamp_gaps']) - 5} more)" if len(data["stamp_gaps"]) > 5 else "") or "none"),
    ]
    rows += [(f"source: {safe_text(role)}", safe_text(where)) for role, where in data["sources"].items()]
    if "readable_frames" in data:
        rows.append(("readable", f"{data['readable_frames']} of {data['frames']}"))
    rows.append(("skipped", str(len(data["skipped"]))))
    for name, value in rows:
        table.add_row(name, value)
    out.print(table)
    for item in data["skipped"][:10]:
        out.print(f"[yellow]skipped[/] {_skip(item)}")
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


def _skipped(out: Any, skipped: list[dict[str, str]]) -> None:
    for item in skipped:
        out.print(f"[yellow]skipped[/] {_skip(item)}")


def show_converted(out: Any, data: dict[str, Any]) -> None:
    """``hiper convert``: frames written, where, in which format, and the frames skipped."""
    if "profile" in data:
        _show_degraded(out, data)
        return
    out.print(f"wrote {data['frames_written']} frames to {safe_text(data['output'])} "
              f"({safe_text(data['to'])})")
    _skipped(out, data["skipped"])


def _show_degraded(out: Any, data: dict[str, Any]) -> None:
    """``hiper convert --degrade``: frames written as the sensor would, and the pose error."""
    err, where = data["pose_error"], safe_text(data["output"])
    out.print(f"wrote {data['frames_written']} frames to {where} as a {data['profile']} sensor "
              f"(seed {data['seed']}); pose error RMS {err['rms_m']:.3f} m, final {err['final_m']:.3f} m; "
              f"truth in {where}/gt")
    _skipped(out, data["skipped"])


def show_replay_start(out: Any, log: object, frames: int, endpoint: str) -> None:
    """``hiper replay`` before the first frame: which log, how many frames, where to."""
    out.print(f"replaying {safe_text(log)} ({frames} frames) on zenoh://{safe_text(endpoint)}")


def show_replayed(out: Any, data: dict[str, Any]) -> None:
    """``hiper replay``: frames published, how long it took, how many were late."""
    out.print(f"published {data['frames']} frames in {data['seconds']:.1f} s ({data['session']}); "
              f"{data['late_frames']} late")
