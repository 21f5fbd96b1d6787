"""Feature learning against known truth: the ODS of 0.6 m/s walkers, bootstrap coverage, the
folded-normal noise, size and altitude, storage as analyses and the CLI."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.analyze.features import FeatureConfig, compute_features, object_dynamics, store_features
from hiper_cli.analyze.stats import bootstrap_mean_ci, folded_normal_sigma
from hiper_cli.analyze.window import TimeWindow
from hiper_cli.cli import app
from hiper_cli.learned import ObjectDynamics, feature_from_analysis
from tests.analyze_scene import track_instance, walk_stand_rows, write_instances


def _people_kb(tmp_path, n=20, seed=0):
    rng = np.random.default_rng(seed)
    people = [
        track_instance(
            walk_stand_rows(rng, 20.0 * k, 0.6, 10.0, 5.0, start=(0.0, k * 0.1)),
            extent=(0.5, 0.4, 1.6 + 0.2 * rng.random()),
            bottom_m=0.02 * rng.random(),
        )
        for k in range(n)
    ]
    chairs = [
        track_instance(
            walk_stand_rows(rng, 5.0 * k, 0.0, 0.0, 30.0, noise_mps=0.01), "chair", extent=(0.5, 0.5, 0.9)
        )
        for k in range(5)
    ]
    return write_instances(tmp_path / "kb", people + chairs)


def test_ods_of_walkers_at_0_6_mps(tmp_path):
    kb = _people_kb(tmp_path)
    report = compute_features(kb, ["person"])
    (person,) = report.classes
    ods = person.ods
    assert ods.mean_mps == pytest.approx(0.6, abs=0.05)
    assert ods.cl_mps <= 0.6 <= ods.cu_mps
    assert ods.mean_lo_mps <= 0.6 <= ods.mean_hi_mps
    assert ods.ratio == pytest.approx(10.0 / 15.0, abs=0.05)  # walking 10 s of every 15 s
    assert 0.02 < ods.sigma_mps < 0.06  # velocity noise 0.03 m/s per axis
    assert ods.instances == 20
    assert 1.6 * 0.2 <= person.size.mean_m3 <= 1.8 * 0.2
    assert person.altitude.lo_m >= 0.0 and person.altitude.hi_m <= 0.02


def test_bootstrap_interval_covers_the_true_mean_in_90_percent_of_seeds():
    true_mean = np.exp(0.5 * 0.4**2)  # lognormal(0, 0.4)
    covered = grouped = 0
    for seed in range(60):
        x = np.random.default_rng(1000 + seed).lognormal(0.0, 0.4, size=60)
        _, lo, hi = bootstrap_mean_ci(x, samples=500, seed=seed)
        covered += lo <= true_mean <= hi
        g = np.repeat(np.arange(20), 3)
        _, lo, hi = bootstrap_mean_ci(x, g, samples=500, seed=seed)
        grouped += lo <= true_mean <= hi
    assert covered / 60 >= 0.9
    assert grouped / 60 >= 0.9


def test_folded_normal_sigma_recovers_the_noise_under_motion():
    rng = np.random.default_rng(3)
    noise = np.abs(rng.normal(0.0, 0.04, 4000))
    motion = rng.uniform(0.4, 0.8, 2000)
    sigma = folded_normal_sigma(np.concatenate([noise, motion]), 2.0, 0.001)
    assert sigma == pytest.approx(0.04, rel=0.08)


def test_features_are_stored_as_typed_analyses_in_the_map_layer(tmp_path):
    kb = _people_kb(tmp_path)
    report = compute_features(kb, window=TimeWindow(0.0, 200.0))
    assert [c.class_name for c in report.classes] == ["chair", "person"]
    chair = report.classes[0].ods
    assert chair.mean_mps is None or chair.ratio < 0.1  # standing still
    stored = store_features(kb, report)
    kinds = sorted((a.kind, a.class_name) for a in stored)
    assert kinds == sorted((k, c) for k in ("ods", "size", "altitude") for c in ("chair", "person"))
    back = [
        a
        for a in kb.load_world(kb.environment("test")).analyses
        if a.kind == "ods" and a.class_name == "person"
    ]
    ods = feature_from_analysis(back[0])
    assert isinstance(ods, ObjectDynamics) and ods == report.classes[1].ods
    kb.sync_graph()
    rows = kb.query('SELECT ?a WHERE { GRAPH ?g { ?a a hiper:Analysis ; hiper:kind "ods" } }')
    assert len(rows) == 2
    # a window before the walkers' second half leaves fewer instances
    assert compute_features(kb, ["person"], TimeWindow(0.0, 100.0)).classes[0].ods.instances == 6


def test_features_cli_json_and_plot(tmp_path):
    kb = _people_kb(tmp_path)
    kb.close()
    out = tmp_path / "features.png"
    result = CliRunner().invoke(
        app,
        [
            "analyze",
            "features",
            "--kb",
            str(tmp_path / "kb"),
            "--class",
            "person",
            "--json",
            "--plot",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    (person,) = data["classes"]
    assert person["ods"]["mean_mps"] == pytest.approx(0.6, abs=0.05)
    assert data["stored"] == 3 and data["plot"] == str(out)
    assert out.stat().st_size > 10_000


def test_features_cli_names_an_unknown_class(tmp_path):
    _people_kb(tmp_path).close()
    result = CliRunner().invoke(
        app, ["analyze", "features", "--kb", str(tmp_path / "kb"), "--class", "unicorn"]
    )
    assert result.exit_code != 0
    assert "unicorn" in result.output and "person" in result.output


def test_column_cache_follows_a_changed_trajectory_and_serves_read_only(tmp_path):
    from hiper_cli.graph import open_kb
    from hiper_cli.graph.columns import trajectory_columns

    rng = np.random.default_rng(5)
    short = track_instance(walk_stand_rows(rng, 0.0, 0.6, 10.0, 0.0))  # 100 rows: inline
    kb = write_instances(tmp_path / "kb", [short])
    first = trajectory_columns(kb.docs, "person")
    assert first.rows.shape == (100, 7)
    assert np.array_equal(first.rows, np.asarray(short.data["trajectory"]))
    longer = walk_stand_rows(rng, 0.0, 0.6, 40.0, 0.0)  # 400 rows: stored apart, in chunks
    short.data["trajectory"] = longer.tolist()
    kb.put_documents([short.to_dict()], env_uuid=kb.environment("test").uuid)
    again = trajectory_columns(kb.docs, "person")
    assert np.array_equal(again.rows, longer)
    kb.close()
    with open_kb(tmp_path / "kb", read_only=True) as ro:
        assert np.array_equal(trajectory_columns(ro.docs, "person").rows, longer)


def test_a_class_that_never_stands_is_all_motion():
    rng = np.random.default_rng(8)
    walking = np.abs(0.6 + rng.normal(0.0, 0.05, 3000))
    ramp = np.linspace(0.0, 0.6, 60)  # a few rows while a new track's speed settles
    speeds = np.concatenate([walking, ramp])
    ods = object_dynamics(speeds, np.arange(speeds.size) // 100, FeatureConfig())
    assert ods.sigma_mps <= 0.15 and ods.ratio > 0.95
    assert ods.mean_mps == pytest.approx(0.6, abs=0.02) and ods.cl_mps <= 0.6 <= ods.cu_mps


def test_a_static_instance_whose_filter_drifted_did_not_move(tmp_path):
    """House 44: standing chairs, tables and beds, their filters drifting as more of them came
    into view (0.1-0.7 m/s at times), made half of all chair rows "dynamic" at 0.38 m/s. The
    tracker's state says they never moved; a chair that was pushed across the room did."""
    rng = np.random.default_rng(3)
    drifting = [
        track_instance(walk_stand_rows(rng, 5.0 * k, 0.0, 0.0, 30.0, noise_mps=0.3), "chair")
        for k in range(4)
    ]
    pushed = track_instance(walk_stand_rows(rng, 0.0, 0.5, 4.0, 6.0), "chair")
    kb = write_instances(tmp_path / "kb", [*drifting, pushed])
    (chair,) = compute_features(kb, ["chair"]).classes
    assert chair.ods.ratio == pytest.approx(4.0 / (4 * 30.0 + 10.0), abs=0.01)  # the push alone
    assert chair.ods.mean_mps == pytest.approx(0.5, abs=0.05)


def test_the_kb_and_the_graph_take_the_speed_from_one_function(tmp_path):
    from hiper_cli.graph.ontology import speed_mps
    from hiper_cli.learned import path_speed_mps

    rng = np.random.default_rng(2)
    inline = track_instance(walk_stand_rows(rng, 0.0, 0.6, 10.0, 0.0, noise_mps=0.0))  # 100 rows
    apart = track_instance(walk_stand_rows(rng, 0.0, 0.9, 40.0, 0.0, noise_mps=0.0))  # 400 rows
    kb = write_instances(tmp_path / "kb", [inline, apart])
    for inst, true in ((inline, 0.6), (apart, 0.9)):
        sql = "SELECT body FROM docs WHERE uuid = ?"
        doc = json.loads(kb.docs.connection.execute(sql, (inst.uuid,)).fetchone()[0])
        assert speed_mps(doc) == pytest.approx(path_speed_mps(inst.data["trajectory"]))
        assert speed_mps(doc) == pytest.approx(true)
    assert (
        "trajectory"
        not in json.loads(
            kb.docs.connection.execute("SELECT body FROM docs WHERE uuid = ?", (apart.uuid,)).fetchone()[0]
        )["data"]
    )


def test_size_and_altitude_of_a_moving_class_ignore_tracks_that_never_move(tmp_path):
    rng = np.random.default_rng(4)
    walkers = [
        track_instance(walk_stand_rows(rng, 20.0 * k, 0.6, 10.0, 2.0), extent=(0.5, 0.4, 1.7))
        for k in range(12)
    ]
    posters = [
        track_instance(
            walk_stand_rows(rng, 7.0 * k, 0.0, 0.0, 20.0, noise_mps=0.005),
            extent=(0.5, 0.02, 0.8),
            bottom_m=1.1,
        )
        for k in range(4)
    ]
    kb = write_instances(tmp_path / "kb", walkers + posters)
    (person,) = compute_features(kb, ["person"]).classes
    assert person.ods.instances == 16 and person.altitude.instances == 12
    assert person.altitude.hi_m < 0.05 and person.size.lo_m3 > 0.3


def test_features_table_holds_one_line_per_class_in_80_columns(tmp_path):
    _people_kb(tmp_path).close()
    result = CliRunner().invoke(app, ["analyze", "features", "--kb", str(tmp_path / "kb"), "--no-store"],
                                env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert any("[c_l, c_u] m/s" in line for line in lines)  # not eaten as markup
    person = [line for line in lines if line.startswith("person ")]
    assert len(person) == 2  # one row in each table, unwrapped
    assert "%" in person[0] and person[1].count("[") == 2
