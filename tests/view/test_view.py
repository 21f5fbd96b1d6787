"""hiper view: the Rerun recording read back with Rerun's own reader, the top-down picture, and
the command without Rerun installed. The scene is the example log perceived with the `truth`
detector (walls, floors, two chairs and a walking person)."""

from __future__ import annotations

import shutil
import sys
from datetime import timedelta
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.graph import open_kb, open_kb_for_reading
from hiper_cli.model import Analysis
from hiper_cli.pipeline import PerceiveOptions, perceive_log
from hiper_cli.view import TimeWindow, ViewRequest, load_scene, render_view
from hiper_cli.view.camera import pick_frames
from hiper_cli.view.floor import floor_images
from hiper_cli.view.style import class_color, entity_path
from tests import REPO_ROOT

ROOT = REPO_ROOT
LOG = ROOT / "fixtures" / "house_small"
# Pictures the tests draw, kept for a person to look at (out/ is not committed).
OUTPUT = ROOT / "out" / "test-output" / "view"
TRUTH = PerceiveOptions(stages=("background", "foreground"),
                        stage_options={"foreground": {"detector": "truth"}})
runner = CliRunner()


@pytest.fixture(scope="module")
def kb_dir(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("view") / "house.hiper"
    perceive_log(LOG, str(path), options=TRUTH)
    return path


def _instances(kb_dir: Path) -> dict[str, set[str]]:
    """class -> uuids of the instances in the KB."""
    with open_kb_for_reading(kb_dir) as kb:
        out: dict[str, set[str]] = {}
        for inst in kb.instances():
            out.setdefault(f"{inst.layer}/{inst.class_name}", set()).add(inst.uuid)
    return out


def _read_rrd(path: Path) -> dict[str, dict]:
    """entity path -> {"rows": n, "stamps_s": [...], "columns": {...}} from Rerun's RRD reader."""
    import rerun.chunk

    entities: dict[str, dict] = {}
    for chunk in rerun.chunk.RrdReader(path).stream():
        entry = entities.setdefault(chunk.entity_path, {"rows": 0, "stamps_s": [], "columns": set()})
        batch = chunk.to_record_batch()
        entry["rows"] += chunk.num_rows
        entry["columns"].update(batch.schema.names)
        if "stamp" in chunk.timeline_names:
            entry["stamps_s"] += [t / timedelta(seconds=1) for t in batch.column("stamp").to_pylist()]
    return entities


def test_recording_holds_the_layers_and_the_logs_time_range(kb_dir, tmp_path):
    pytest.importorskip("rerun", reason="rerun-sdk (the hiper[view] extra) is not installed")
    out = tmp_path / "scene.rrd"
    summary = render_view(ViewRequest(str(kb_dir), rrd=out, log=LOG, image_hz=2.0))
    entities = _read_rrd(out)
    instances = _instances(kb_dir)
    for key in ("background/wall", "background/floor", "foreground/person", "foreground/chair"):
        for uuid in instances[key]:
            assert f"/{key}/{uuid}" in entities, f"/{key}/{uuid} missing"
    assert len(instances["background/wall"]) >= 3 and len(instances["foreground/person"]) >= 1
    # The robot's path, its moving camera (one pose per frame) and the log's images at 2 Hz.
    assert "/robot/path" in entities
    camera = entities["/robot/camera"]["stamps_s"]
    assert len(camera) == 60 and min(camera) == 0.0 and max(camera) == pytest.approx(14.75)
    rgb = entities["/robot/camera/image/rgb"]["stamps_s"]
    assert len(rgb) == 30 == summary.frames_logged and rgb[:3] == [0.0, 0.5, 1.0]
    assert "/robot/camera/image/depth" in entities and "/robot/camera/image/blobs" in entities
    # Everything in time lies in the log's range (a box is cleared one hold after it was seen).
    stamps = [t for e in entities.values() for t in e["stamps_s"]]
    assert min(stamps) == 0.0 and 14.75 <= max(stamps) <= 14.75 + 0.5 + 1e-9
    # A person is a box at each sighting, cleared when unseen, with its speed and path.
    person = next(iter(instances["foreground/person"]))
    path = f"/foreground/person/{person}"
    assert "Clear:is_recursive" in entities[path]["columns"]
    assert "Boxes3D:labels" in entities[path]["columns"]
    assert f"{path}/trajectory" in entities and f"{path}/speed_mps" in entities
    assert summary.rrd_bytes == out.stat().st_size
    import rerun.chunk

    assert len(rerun.chunk.RrdReader(out).blueprints()) == 1  # the layout it opens with


def test_time_window_cuts_the_recording(kb_dir, tmp_path):
    pytest.importorskip("rerun", reason="rerun-sdk (the hiper[view] extra) is not installed")
    out = tmp_path / "window.rrd"
    render_view(ViewRequest(str(kb_dir), rrd=out, window=TimeWindow(6.0, 9.0)))
    entities = _read_rrd(out)
    camera = entities["/robot/camera"]["stamps_s"]
    assert min(camera) == 6.0 and max(camera) == 9.0
    assert not any(p.startswith("/robot/camera/image/rgb") for p in entities)  # no --log
    with open_kb_for_reading(kb_dir) as kb:
        outside = [i.uuid for i in kb.instances() if i.last_seen_s < 6.0]
    assert outside and not any(p.endswith(u) for p in entities for u in outside)


def test_topdown_png_draws_the_scene(kb_dir):
    out = OUTPUT / "house_small_topdown.png"
    summary = render_view(ViewRequest(str(kb_dir), png=out))
    image = cv2.imread(str(out))
    assert image is not None and (image.shape[1], image.shape[0]) == summary.png_size_px
    assert image.shape[0] > 300 and image.shape[1] > 300
    for cls in ("wall", "floor", "person", "chair"):
        b, g, r = (int(v) for v in class_color(cls)[::-1])
        hits = np.all(np.abs(image.astype(int) - [b, g, r]) <= 2, axis=2).sum()
        assert hits > 30, f"no {cls} colour in the picture"


def test_png_works_and_rrd_says_how_to_install_without_rerun(kb_dir, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun raises ImportError
    result = runner.invoke(app, ["view", "--kb", str(kb_dir), "-o", str(tmp_path / "x.rrd")])
    assert result.exit_code == 2
    assert "pip install 'hiper[view]'" in result.output and len(result.output.strip().splitlines()) == 1
    assert not (tmp_path / "x.rrd").exists()
    result = runner.invoke(app, ["view", "--kb", str(kb_dir), "--png", str(tmp_path / "x.png"), "--json"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "x.png").stat().st_size > 10_000


def test_cli_errors_name_the_fix(kb_dir, tmp_path):
    result = runner.invoke(app, ["view", "--kb", str(kb_dir)])
    assert result.exit_code == 2 and "pass -o scene.rrd, --spawn or --png" in result.output
    result = runner.invoke(app, ["view", "--kb", str(kb_dir), "-o", str(tmp_path / "a.mp4")])
    assert result.exit_code == 2 and "a.rrd" in result.output
    result = runner.invoke(app, ["view", "--kb", str(kb_dir), "--png", "x.png", "--from", "9", "--to", "3"])
    assert result.exit_code == 2 and "swap them" in result.output
    result = runner.invoke(app, ["view", "--kb", str(tmp_path / "none.hiper"), "--png", "x.png"])
    assert result.exit_code == 1 and "hiper perceive" in result.output


def test_heatmaps_lie_on_the_floor(kb_dir, tmp_path):
    copy = tmp_path / "with_heatmap.hiper"
    shutil.copytree(kb_dir, copy)
    grid = np.zeros((20, 30))
    grid[5:10, 10:20] = 3.0
    heat = Analysis("heatmap", "person", 0.0, 15.0, {"grid": grid.tolist(), "resolution_m": 0.2,
                                                     "origin_m": [1.0, 0.0]}, created_s=1.0)
    with open_kb(copy) as kb:
        kb.put_analyses([heat])
        scene = load_scene(kb)
    assert [f.name for f in scene.floor] == ["heatmap/person"]
    assert scene.floor[0].extent_m == (1.0, 7.0, 0.0, 4.0)
    render_view(ViewRequest(str(copy), png=OUTPUT / "house_small_heatmap.png"))
    pytest.importorskip("rerun", reason="rerun-sdk (the hiper[view] extra) is not installed")
    render_view(ViewRequest(str(copy), rrd=tmp_path / "heat.rrd"))
    assert "/map/heatmap/person" in _read_rrd(tmp_path / "heat.rrd")


def test_floor_images_skip_what_is_not_a_grid():
    docs = [
        {"kind": "ods", "class": "person", "t_start_s": 0, "t_end_s": 1, "values": {"mean_mps": 1.0}},
        {"kind": "heatmap", "class": "cup", "t_start_s": 0, "t_end_s": 1, "values": {"grid": [1, 2]}},
        {"kind": "heatmap", "class": "chair", "t_start_s": 50, "t_end_s": 60, "created_s": 1,
         "values": {"grid": [[1.0]], "resolution_m": 0.1, "origin_m": [0, 0]}},
    ]
    env = [{"map": {"image": [[0, 100], [100, 0]], "resolution_m": 0.05, "origin_m": [-1, -1, 0]}}]
    images = floor_images(docs, env, TimeWindow(None, 10.0))
    assert [(f.name, f.grid.shape) for f in images] == [("occupancy", (2, 2))]


def test_pick_frames_subsamples_to_the_rate():
    stamps = np.arange(0, 10, 0.25)
    assert pick_frames(stamps, TimeWindow(), 2.0) == list(range(0, 40, 2))
    assert pick_frames(stamps, TimeWindow(), 0.0) == list(range(40))
    assert pick_frames(stamps, TimeWindow(2.0, 3.0), 1.0) == [8, 12]


def test_live_view_streams_perception_as_it_runs(tmp_path):
    pytest.importorskip("rerun", reason="rerun-sdk (the hiper[view] extra) is not installed")
    from hiper_cli.view.live import LiveView

    out = tmp_path / "live.rrd"
    live = LiveView.open(out=out, image_hz=1.0)
    perceive_log(LOG, str(tmp_path / "live.hiper"), options=TRUTH, on_frame=live)
    live.close()
    with open_kb_for_reading(tmp_path / "live.hiper") as kb:
        instances = kb.instances()
    entities = _read_rrd(out)
    assert len(entities["/robot/camera"]["stamps_s"]) == 60
    assert len(entities["/robot/camera/image/rgb"]["stamps_s"]) == 15
    assert {"background", "foreground"} == {i.layer for i in instances}
    for inst in instances:
        assert entity_path(inst.layer, inst.class_name, inst.uuid) in entities
    people = [p for p in entities if p.startswith("/foreground/person/")]
    assert people and any("Clear:is_recursive" in entities[p]["columns"] for p in people)


def test_floor_images_read_the_forms_hiper_analyze_stores(tmp_path):
    import base64
    import zlib

    occ = np.full((4, 6), -1, dtype=np.int8)
    occ[1:3, 1:5] = 0
    occ[0, :] = 100  # bottom row (y0) occupied
    env = [{"map": {"resolution_m": 0.5, "origin_m": [-1.0, -2.0, 0.0], "width": 6, "height": 4,
                    "encoding": "int8 rows bottom-up, zlib, base64",
                    "cells": base64.b64encode(zlib.compress(occ.tobytes())).decode()}}]
    heat = np.zeros((4, 6), dtype=np.uint8)
    heat[3, 5] = 80  # top-right cell hot, 255 unknown
    heat[0, 0] = 255
    pgm = tmp_path / "heatmap_person_keepout.pgm"
    cv2.imwrite(str(pgm), np.flipud(heat))  # map_server: row 0 at the top
    docs = [{"kind": "heatmap", "class": "person", "t_start_s": 0, "t_end_s": 9, "created_s": 1,
             "values": {"resolution_m": 0.5, "origin_m": [-1.0, -2.0, 0.0], "shape": [4, 6],
                        "files": {"png": str(tmp_path / "x.png"), "keepout_pgm": str(pgm)}}},
            {"kind": "heatmap", "class": "cup", "t_start_s": 0, "t_end_s": 9,
             "values": {"resolution_m": 0.5, "origin_m": [0, 0], "files": {"keepout_pgm": "/gone.pgm"}}}]
    heatmap, occupancy = floor_images(docs, env, TimeWindow())
    assert (heatmap.name, occupancy.name) == ("heatmap/person", "occupancy")
    assert heatmap.grid[3, 5] == 80 and np.isnan(heatmap.grid[0, 0]) and heatmap.grid.shape == (4, 6)
    np.testing.assert_array_equal(occupancy.grid, occ)
    assert occupancy.extent_m == (-1.0, 2.0, -2.0, 0.0)
    rgba = occupancy.rgba()
    assert rgba[0, 0, 3] > 100 > rgba[1, 1, 3] > 0 == rgba[3, 0, 3]  # occupied, free, unknown
    assert heatmap.rgba()[3, 5, 3] == 220 and heatmap.rgba()[0, 0, 3] == 0 == heatmap.rgba()[1, 1, 3]


def test_perceive_view_streams_to_rerun_and_says_how_to_install(tmp_path, monkeypatch):
    pytest.importorskip("rerun", reason="rerun-sdk (the hiper[view] extra) is not installed")
    from hiper_cli.view import live as live_module

    out = tmp_path / "watched.rrd"
    opened = []

    def open_to_file(**kwargs):  # no display here: the viewer's stream goes to a file instead
        opened.append(kwargs)
        return live_module.LiveView(live_module.new_recording(out, False, with_images=True))

    monkeypatch.setattr(live_module.LiveView, "open", staticmethod(open_to_file))
    args = ["perceive", str(LOG), "--kb", str(tmp_path / "w.hiper"), "--detector", "truth", "--json"]
    result = runner.invoke(app, [*args, "--view"])
    assert result.exit_code == 0, result.output
    assert opened == [{"spawn": True}]
    assert len(_read_rrd(out)["/robot/camera"]["stamps_s"]) == 60
    monkeypatch.setitem(sys.modules, "rerun", None)
    result = runner.invoke(app, [*args[:3], str(tmp_path / "x.hiper"), *args[4:], "--view"])
    assert result.exit_code == 2 and "pip install 'hiper[view]'" in result.output


def _jittery_track(state: str):
    """A table seen 12 times, its sightings scattered over 3 m (segmentation noise), 1 m/s."""
    from hiper_cli.model import Box3D
    from hiper_cli.view.scene import TrackItem

    stamps = np.arange(12, dtype=float) * 0.25
    centers = np.column_stack([np.linspace(0, 3, 12), 0.3 * (-1.0) ** np.arange(12), np.full(12, 0.4)])
    return TrackItem("0190-aaaa", "table", state, Box3D(np.array([1.5, 0.0, 0.4]), np.array([1.0, 0.6, 0.8])),
                     stamps, centers, np.ones(12))


def test_a_static_instance_is_drawn_without_path_or_speed():
    from hiper_cli.view.scene import ViewScene
    from hiper_cli.view.style import speed_colors
    from hiper_cli.view.topdown import render_topdown

    path_bgr = speed_colors(np.array([1.0]))[0][::-1].astype(int)

    def path_pixels(state: str) -> int:
        scene = ViewScene("t.hiper", TimeWindow(), (), (_jittery_track(state),), (), ())
        image = render_topdown(scene).astype(int)
        return int(np.all(np.abs(image - path_bgr) <= 2, axis=2).sum())

    assert path_pixels("dynamic") > 200  # a mover's path, in its speed colour
    assert path_pixels("static") < 40  # only the legend's speed ramp


def test_static_instances_in_the_recording_have_no_path_or_speed(kb_dir, tmp_path):
    pytest.importorskip("rerun", reason="rerun-sdk (the hiper[view] extra) is not installed")
    out = tmp_path / "static.rrd"
    render_view(ViewRequest(str(kb_dir), rrd=out))
    entities = _read_rrd(out)
    with open_kb_for_reading(kb_dir) as kb:
        static = [i for i in kb.instances() if i.layer == "foreground" and i.state == "static"]
    assert static
    for inst in static:
        path = entity_path("foreground", inst.class_name, inst.uuid)
        assert f"{path}/trajectory" not in entities and f"{path}/speed_mps" not in entities
        assert entities[path]["stamps_s"] == [pytest.approx(inst.first_seen_s)]  # one fused box, kept
