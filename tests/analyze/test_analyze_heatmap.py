"""Heatmaps against known truth: the hospital's crowded corridor hot, the empty one cold; nav2
masks that round-trip through map_server's rules; the map layer; the CLI."""

import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.analyze import TimeWindow, generate_heatmap, read_map_server, resolve_window
from hiper_cli.analyze.costmap import keepout_mask
from hiper_cli.analyze.gridmap import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, write_map_server
from hiper_cli.analyze.maplayer import build_map, environment_of, load_map
from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.model import Instance
from tests import REPO_ROOT
from tests.analyze_scene import hospital_people_rows, track_instance, write_instances

TEST_OUT = Path(os.environ.get("HIPER_TEST_OUT", REPO_ROOT / "out" / "tests"))


@pytest.fixture(scope="module")
def hospital(tmp_path_factory):
    """A KB holding the hospital's background (walls, floor) and 90 s of its five walkers."""
    rows, world = hospital_people_rows(seconds=90.0)
    people = [track_instance(r) for r in rows]
    background = [
        Instance("background", o.class_name, o.box, 0.0, 0.0)
        for o in world.objects
        if o.layer == "background"
    ]
    path = tmp_path_factory.mktemp("hospital") / "kb"
    write_instances(path, people + background, env="hospital").close()
    return path, world


def _corridors(world):
    cw = world.walkable[0][3] + 0.6  # corridor A: y in [0, cw]; corridor B: the top band of cw
    x0, _, x1, y1 = world.bounds
    return (x0 + 3.0, 0.6, x1 - 3.0, cw - 0.6), (x0 + 3.0, y1 - cw + 0.6, x1 - 3.0, y1 - 0.6)


def _mean_heat(hm, rect):
    x0, y0, x1, y1 = rect
    xs, ys = np.meshgrid(np.arange(x0, x1, 0.1), np.arange(y0, y1, 0.1))
    iy, ix, inside = hm.grid.cell_of(np.column_stack([xs.ravel(), ys.ravel()]))
    assert inside.all()
    return float(hm.heat[iy, ix].mean()), float(hm.heat[iy, ix].max())


def test_the_crowded_corridor_is_hot_and_the_empty_one_cold(hospital, tmp_path):
    from hiper_cli.graph import open_kb

    path, world = hospital
    with open_kb(path) as kb:
        result = generate_heatmap(kb, "person", out_dir=TEST_OUT, inverse=True)
        hm = result.heatmap
        corridor_a, corridor_b = _corridors(world)
        a_mean, a_max = _mean_heat(hm, corridor_a)
        _, b_max = _mean_heat(hm, corridor_b)
        assert a_max == pytest.approx(0.8, abs=0.01)  # the cap: peak occupancy 80 %
        assert a_mean > 0.15 and b_max < 0.01
        assert float(hm.heat.max()) <= 0.8 + 1e-6
        # the inverse map draws a search into corridor A
        iy, ix, _ = hm.grid.cell_of(np.array([[12.0, 1.3], [12.0, world.bounds[3] - 1.3]]))
        assert hm.inverse[iy[0], ix[0]] < hm.inverse[iy[1], ix[1]]
        assert result.speed_source == "these rows"
        assert hm.speed_mps == pytest.approx(0.6, abs=0.05)
        analyses = [d for d in kb.docs.find(type="analysis") if d["kind"] == "heatmap"]
        assert len(analyses) == 1 and analyses[0]["values"]["files"]["png"].endswith("heatmap_person.png")
    assert Path(result.files["png"]).stat().st_size > 20_000
    assert Path(result.files["inverse_png"]).exists()


def test_nav2_masks_round_trip_through_map_server_rules(hospital, tmp_path):
    from hiper_cli.graph import open_kb

    path, _ = hospital
    with open_kb(path) as kb:
        result = generate_heatmap(kb, "person", out_dir=tmp_path, store=False)
    hm, files = result.heatmap, result.files
    keepout = read_map_server(files["keepout_yaml"])
    assert keepout.resolution_m == hm.grid.resolution_m and keepout.origin_xy_m == hm.grid.origin_xy_m
    known = hm.grid.cells != UNKNOWN
    expected = keepout_mask(hm.heat, known, None).astype(np.int16)
    expected[expected == 255] = UNKNOWN
    assert np.array_equal(keepout.cells, expected)
    assert keepout.cells.max() == 80 and (keepout.cells == UNKNOWN).any()  # cap 80 %, never 100
    iy, ix, _ = keepout.cell_of(np.array([[12.0, 1.3]]))  # a point in the crowded corridor
    assert keepout.cells[iy[0], ix[0]] > 20
    text = Path(files["keepout_yaml"]).read_text()
    assert "mode: raw" in text and "origin: [" in text and ", 0.0]" in text
    speed = read_map_server(files["speed_yaml"])
    cold = known & (hm.heat < 0.001)
    assert (speed.cells[cold] == 0).all()  # 0 = no limit in nav2's speed filter
    assert speed.cells[iy[0], ix[0]] < 100 and speed.cells[known].min() == 0
    assert speed.cells[(speed.cells > 0)].min() >= 30
    params = Path(files["filter_params"]).read_text()
    assert "type: 0" in params and "type: 1" in params and "multiplier: 1.0" in params
    assert "nav2_costmap_2d::KeepoutFilter" in Path(files["costmap_snippet"]).read_text()


def test_map_server_reader_applies_trinary_scale_and_negate(tmp_path):
    import cv2

    pixels = np.array([[0, 254, 205, 100]], dtype=np.uint8)  # image row 0 = top of the map
    cv2.imwrite(str(tmp_path / "m.pgm"), pixels)
    base = (
        "image: m.pgm\nresolution: 0.1\norigin: [1.0, 2.0, 0.0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    (tmp_path / "t.yaml").write_text(base + "negate: 0\nmode: trinary\n")
    (tmp_path / "n.yaml").write_text(base + "negate: 1\nmode: trinary\n")
    (tmp_path / "s.yaml").write_text(base + "negate: 0\nmode: scale\n")
    (tmp_path / "r.yaml").write_text(base + "negate: 1\nmode: raw\n")
    assert read_map_server(tmp_path / "t.yaml").cells.tolist() == [[OCCUPIED, FREE, UNKNOWN, UNKNOWN]]
    assert read_map_server(tmp_path / "n.yaml").cells.tolist() == [[FREE, OCCUPIED, OCCUPIED, UNKNOWN]]
    # scale: occ = (255 - 100) / 255 = 0.608 -> (0.608 - 0.196) / (0.65 - 0.196) * 100 = 91
    assert read_map_server(tmp_path / "s.yaml").cells.tolist() == [[OCCUPIED, FREE, 0, 91]]  # 205: occ 0.1961
    assert read_map_server(tmp_path / "r.yaml").cells.tolist() == [
        [0, UNKNOWN, UNKNOWN, 100]
    ]  # raw ignores negate
    with pytest.raises(ConfigError, match="mode 'fancy'"):
        (tmp_path / "x.yaml").write_text(base + "mode: fancy\n")
        read_map_server(tmp_path / "x.yaml")


def test_trinary_map_export_round_trips_with_rows_top_down(tmp_path):
    cells = np.full((3, 4), UNKNOWN, dtype=np.int8)
    cells[0, :] = FREE  # the bottom row (smallest y)
    cells[2, 3] = OCCUPIED  # top right
    grid = OccupancyGrid(cells, 0.5, (-1.0, -2.0))
    yaml_p, pgm = write_map_server(grid, tmp_path / "map.yaml")
    import cv2

    image = cv2.imread(str(pgm), cv2.IMREAD_UNCHANGED)
    assert image[0, 3] == 0 and image[2, 0] == 254  # image row 0 is the top of the map
    back = read_map_server(yaml_p)
    assert np.array_equal(back.cells, cells) and back.origin_xy_m == (-1.0, -2.0)


def test_map_layer_from_the_background_is_stored_in_the_environment(hospital):
    from hiper_cli.graph import open_kb

    path, world = hospital
    with open_kb(path) as kb:
        grid = build_map(kb)
        env = environment_of(kb)
        iy, ix, inside = grid.cell_of(np.array([[12.0, 1.3], [world.bounds[2] - 0.03, 3.0], [12.0, 2.0]]))
        assert inside.all()
        assert grid.cells[iy[0], ix[0]] == FREE  # corridor floor
        assert grid.cells[iy[1], ix[1]] == OCCUPIED  # the east wall
        generate_heatmap(kb, "person", out_dir=path.parent / "o")  # stores the map it drew on
        stored = load_map(kb.environment("hospital"))
        assert stored is not None and np.array_equal(stored.cells, grid.cells)
        assert env.name == "hospital"


def test_time_windows():
    w = resolve_window(last="30s", newest_stamp_s=100.0)
    assert (w.t_start_s, w.t_end_s) == (70.0, 100.0)
    d = resolve_window(daily="09:00-10:00")
    stamps = np.array([9 * 3600.0, 9.5 * 3600 + 86400, 10 * 3600.0, 8 * 3600.0])
    assert d.mask(stamps).tolist() == [True, True, False, False]
    night = TimeWindow(daily_s=(23 * 3600.0, 1 * 3600.0))
    assert night.mask(np.array([23.5 * 3600, 0.5 * 3600, 12 * 3600])).tolist() == [True, True, False]
    with pytest.raises(ConfigError, match="--last"):
        resolve_window(last="1h", t_from="3")
    with pytest.raises(ConfigError, match="HH:MM-HH:MM"):
        resolve_window(daily="9")
    assert resolve_window(t_from="1970-01-01T00:01").t_start_s == 60.0


def test_heatmap_window_selects_rows(hospital, tmp_path):
    from hiper_cli.graph import open_kb

    path, _ = hospital
    with open_kb(path) as kb:
        full = generate_heatmap(kb, "person", out_dir=tmp_path, store=False).heatmap
        part = generate_heatmap(kb, "person", TimeWindow(0.0, 30.0), out_dir=tmp_path, store=False).heatmap
    assert full.rows == 5 * 90 * 5 and part.rows == 5 * 151 and part.instances == 5  # 5 Hz, [0, 30] s


def test_a_window_with_no_rows_is_a_one_line_error_that_stores_nothing(hospital, tmp_path):
    """A window after the data or a daily span the log never saw crashed in OpenCV's blur."""
    from hiper_cli.graph import open_kb

    path, _ = hospital
    with open_kb(path) as kb:
        before = kb.docs.count(type="analysis"), kb.docs.find(type="environment")
    runner = CliRunner()
    for window in (["--from", "1000"], ["--daily", "09:00-17:00"]):
        r = runner.invoke(app, ["analyze", "heatmap", "--class", "person", "--kb", str(path), *window,
                                "-o", str(tmp_path)])
        text = " ".join(r.output.split())
        assert r.exit_code == 1 and "Traceback" not in r.output, r.output
        assert "no person trajectory rows in the window" in text and "holds them from 0.0 to 89.8 s" in text
    with open_kb(path) as kb:
        assert (kb.docs.count(type="analysis"), kb.docs.find(type="environment")) == before  # no map stored


def test_heatmap_cli_json_and_errors(hospital, tmp_path):
    path, _ = hospital
    runner = CliRunner()
    result = runner.invoke(
        app,
        [
            "analyze",
            "heatmap",
            "--class",
            "person",
            "--kb",
            str(path),
            "--last",
            "60s",
            "-o",
            str(tmp_path),
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["window"]["t_start_s"] == pytest.approx(data["window"]["t_end_s"] - 60.0)
    assert set(data["files"]) >= {
        "png",
        "keepout_yaml",
        "keepout_pgm",
        "speed_yaml",
        "filter_params",
        "costmap_snippet",
    }
    bad = runner.invoke(
        app, ["analyze", "heatmap", "--class", "unicorn", "--kb", str(path), "-o", str(tmp_path)]
    )
    assert bad.exit_code != 0 and "unicorn" in bad.output and "person" in bad.output
    missing = runner.invoke(
        app, ["analyze", "heatmap", "--kb", str(path), "--map", str(tmp_path / "no.yaml")]
    )
    assert missing.exit_code != 0 and "no.yaml" in missing.output
    m = runner.invoke(
        app, ["analyze", "map", "--kb", str(path), "-o", str(tmp_path / "floor.yaml"), "--json"]
    )
    assert m.exit_code == 0, m.output
    assert json.loads(m.output)["occupied_cells"] > 0 and (tmp_path / "floor.pgm").exists()


def test_outputs_that_cannot_be_written_get_one_line_errors(hospital, tmp_path):
    path, _ = hospital
    runner = CliRunner()
    a_file = tmp_path / "maps"
    a_file.write_text("not a folder")
    heat = runner.invoke(app, ["analyze", "heatmap", "--kb", str(path), "-o", str(a_file)])
    assert heat.exit_code != 0 and "not a folder" in heat.output
    assert a_file.read_text() == "not a folder"
    plain = runner.invoke(app, ["analyze", "map", "--kb", str(path), "-o", str(tmp_path / "floor")])
    assert plain.exit_code != 0 and ".yaml" in plain.output
    assert not (tmp_path / "floor").exists() and not (tmp_path / "floor.pgm").exists()
