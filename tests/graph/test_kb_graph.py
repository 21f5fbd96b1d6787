"""The knowledge base, run against both graph backends: the on-disk pyoxigraph store and a
SPARQL 1.1 endpoint (an ``oxigraph serve`` process on loopback)."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.errors import KnowledgeBaseError
from hiper_cli.graph import KbConfig, open_kb
from hiper_cli.graph.ontology import layer_graph, ontology_turtle
from hiper_cli.model import Analysis, Box3D, Instance, Observation
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import FrameResult
from tests import kb_helpers
from tests.kb_helpers import ProbeStage, make_frame

sparql_url = kb_helpers.sparql_url  # fixtures shared with test_kb_exchange
kb_location = kb_helpers.kb_location


def _fill(kb, n_frames=12):
    env = kb.environment("lab")
    session = kb.start_session(env, "/logs/lab", ["probe"])
    stage = ProbeStage()

    def on_frame(frame, result):
        if frame is None:
            kb.write_frame(session, result)
        else:
            kb.write_frame(session, result, pose_id=frame.pose_id, stamp_s=frame.stamp_s,
                           T_map_cam=frame.T_map_cam)

    world, _ = run_stages([make_frame(i, x_m=0.5 * i) for i in range(n_frames)], [stage], None, on_frame)
    kb.end_session(session)
    return env, session, world


def test_frames_become_documents_and_graph_nodes(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _env, session, world = _fill(kb)
        kb.sync_graph()
        assert kb.docs.count(type="observation") == 24
        # 12 frames, tracks of 4 frames -> 3 tracks; frames 5 and 11 each merge the previous away
        assert {i.uuid for i in kb.instances()} == set(world.background) | set(world.foreground)
        assert kb.docs.count(type="instance", layer="foreground") == 1
        counts = kb.graph_counts()
        assert counts == kb.document_counts()
        # observations are summarised: one batch per instance, session and minute
        assert "foreground/Observation" not in counts
        assert counts["foreground/ObservationBatch"] == 1 == counts["foreground/wasDerivedFrom"]
        assert counts["background/ObservationBatch"] == kb.docs.count(type="instance", layer="background")
        report = kb.check(repair=False)
        assert report.ok, report.problems
        assert kb.docs.session(session.id).frames == 12


def test_graph_nodes_carry_high_level_attributes(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _, _, world = _fill(kb)
        kb.sync_graph()
        floor = next(iter(world.background.values()))
        rows = kb.query(
            f"SELECT ?cls ?last ?state ?n ?center WHERE {{ GRAPH {layer_graph(kb.kb_id, 'background')} {{ "
            f"<urn:uuid:{floor.uuid}> hiper:className ?cls ; hiper:lastSeenS ?last ; hiper:state ?state ; "
            "hiper:observationCount ?n ; hiper:boxCenterM ?center } }"
        )
        assert len(rows) == 1
        assert rows[0]["cls"].value == "floor"
        assert float(rows[0]["last"].value) == pytest.approx(floor.last_seen_s)
        assert int(rows[0]["n"].value) == 12
        derived = kb.query(f"SELECT (SUM(?k) AS ?n) WHERE {{ GRAPH ?g {{ <urn:uuid:{floor.uuid}> "
                           "prov:wasDerivedFrom ?b . ?b a hiper:ObservationBatch ; "
                           "hiper:observationCount ?k } }")
        assert int(derived[0]["n"].value) == 12


def test_summary_detail_keeps_a_node_per_observation(tmp_path):
    with open_kb(tmp_path / "kb", config=KbConfig(observation_detail="summary")) as kb:
        _, _, world = _fill(kb)
        kb.sync_graph()
        counts = kb.graph_counts()
        assert counts == kb.document_counts()
        assert counts["foreground/Observation"] == 12 and counts["background/wasDerivedFrom"] == 12
        floor = next(iter(world.background.values()))
        derived = kb.query(f"SELECT (COUNT(?o) AS ?n) WHERE {{ GRAPH ?g {{ <urn:uuid:{floor.uuid}> "
                           "prov:wasDerivedFrom ?o . ?o a hiper:Observation } }")
        assert int(derived[0]["n"].value) == 12
        assert kb.check(repair=False).ok


def test_reopen_keeps_everything_and_world_reloads(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _env, _, world = _fill(kb)
    with open_kb(location, docs_dir=docs) as kb:
        assert kb.check(repair=False).ok
        loaded = kb.load_world(kb.environment("lab"))
        assert set(loaded.background) == set(world.background)
        assert set(loaded.foreground) == set(world.foreground)
        floor = next(iter(loaded.background.values()))
        assert len(floor.observation_uuids) == 12
        assert floor.observation_uuids == next(iter(world.background.values())).observation_uuids


def test_document_queries(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _, _, world = _fill(kb)
        cups = kb.docs.find(type="observation", class_name="cup", t_start_s=10.2, t_end_s=10.5)
        assert [round(d["stamp_s"], 3) for d in cups] == [10.2, 10.3, 10.4, 10.5]
        track = next(iter(world.foreground.values()))
        obs = kb.docs.observations_of(track.uuid)
        assert [o["uuid"] for o in obs] == track.observation_uuids
        # frame 3: camera at x=1.5, cup 0.3 m right of it -> map x = 1.8; the spatial index
        # holds the map-frame box of each observation
        hits = kb.docs.in_box([1.75, -0.1, 0.9], [1.85, 0.1, 1.1], type="observation")
        assert [h["pose_id"] for h in hits] == [3]
        assert kb.docs.get(hits[0]["uuid"])["class"] == "cup"
        assert kb.docs.get("no-such-uuid") is None


def test_deleted_instances_leave_the_graph(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _fill(kb)
        kb.sync_graph()
        dead = [u for u, _, _ in kb.docs.tombstones(0, kb.docs.seq)]
        assert len(dead) == 2
        for uuid in dead:
            assert kb.query(f"SELECT ?p WHERE {{ GRAPH ?g {{ <urn:uuid:{uuid}> ?p ?o }} }}") == []


def test_check_repairs_a_damaged_graph(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _fill(kb)
        kb.sync_graph()
        kb.graph.clear([layer_graph(kb.kb_id, "foreground")])  # lose a layer behind the KB's back
        report = kb.check(repair=False)
        assert not report.ok
        assert any("foreground/ObservationBatch: graph 0 vs documents 1" in p for p in report.problems)
        report = kb.check(repair=True)
        assert report.repaired and report.ok
        assert kb.check(repair=False).ok


def test_check_finds_a_wrong_attribute(kb_location):
    import pyoxigraph as ox

    from hiper_cli.graph.ontology import h, node

    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _, _, world = _fill(kb)
        kb.sync_graph()
        floor = next(iter(world.background.values()))
        g = layer_graph(kb.kb_id, "background")
        kb.graph.write(kb.kb_id, [node(floor.uuid).value], [],  # same counts, wrong class
                       [ox.Quad(node(floor.uuid), h("className"), ox.Literal("ceiling"), g)])
        report = kb.check(repair=False)
        assert not report.ok
        assert any("triples missing" in p for p in report.problems), report.problems
        assert kb.check(repair=True).ok and kb.check(repair=False).ok


def test_graph_catches_up_from_the_high_water_mark(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _fill(kb)
        kb.sync_graph()
        synced = kb.graph.synced_seq(kb.kb_id)
        assert synced == kb.docs.seq
        env = kb.environment("lab")
        session = kb.start_session(env, "/logs/lab2", ["probe"])
        book = Instance("foreground", "book", Box3D(np.zeros(3), np.ones(3)), 20.0, 20.0)
        obs = Observation("foreground", "book", 0.7, 20.0, 0, Box3D(np.zeros(3), np.ones(3)),
                          instance_uuid=book.uuid)
        book.observation_uuids.append(obs.uuid)
        kb.write_frame(session, FrameResult([obs], [book]), pose_id=0, stamp_s=20.0, T_map_cam=np.eye(4))
        assert kb.graph.synced_seq(kb.kb_id) == synced  # the graph lags until the next sync
        assert not kb.check(repair=False).ok
        report = kb.sync_graph()
        assert report.documents == 1 and report.links == 1 and report.sessions == 1  # instance, batch
        assert kb.check(repair=False).ok


def test_analyses_and_multi_session_environment(kb_location):
    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        _fill(kb)
        kb.put_analyses([Analysis("ods", "cup", 0.0, 10.0, {"mean_mps": 0.4}, 1.0)])
        env = kb.environment("lab")
        assert kb.environment("lab").uuid == env.uuid
        assert len(kb.environments()) == 1
        kb.sync_graph()
        rows = kb.query('SELECT ?v WHERE { GRAPH ?g { ?a a hiper:Analysis ; hiper:kind "ods" ; '
                        "hiper:valuesJson ?v } }")
        assert rows and '"mean_mps": 0.4' in rows[0]["v"].value
        assert kb.load_world(env).analysis("ods", "cup") is not None


def test_two_knowledge_bases_share_one_endpoint(sparql_url, tmp_path):
    with open_kb(sparql_url, docs_dir=tmp_path / "robot1") as kb1, \
            open_kb(sparql_url, docs_dir=tmp_path / "robot2") as kb2:
        _fill(kb1, 6)
        _fill(kb2, 3)
        kb1.sync_graph()
        kb2.sync_graph()
        assert kb1.kb_id != kb2.kb_id
        assert kb1.check(repair=False).ok and kb2.check(repair=False).ok
        rows = kb1.query("SELECT (SUM(?k) AS ?n) WHERE { GRAPH ?g { ?b a hiper:ObservationBatch ; "
                         "hiper:observationCount ?k } }")
        assert int(rows[0]["n"].value) >= 18  # both robots' observations on one endpoint


def test_errors_name_the_problem(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(KnowledgeBaseError, match="is a file, not a knowledge-base directory"):
        open_kb(tmp_path / "file")
    with pytest.raises(KnowledgeBaseError, match="no knowledge base there"):
        open_kb(tmp_path / "missing", read_only=True)
    with pytest.raises(KnowledgeBaseError, match="no SPARQL endpoint answers"):
        open_kb("http://127.0.0.1:9", docs_dir=tmp_path / "d")
    with pytest.raises(KnowledgeBaseError, match="observation_detail"):
        KbConfig(observation_detail="everything")
    (tmp_path / "bad.hiper").mkdir()
    (tmp_path / "bad.hiper" / "documents.sqlite").write_bytes(b"not a database at all" * 100)
    with pytest.raises(KnowledgeBaseError, match="not a hiper document store"):
        open_kb(tmp_path / "bad.hiper")


def test_full_observation_detail(tmp_path):
    with open_kb(tmp_path / "kb", config=KbConfig(observation_detail="full")) as kb:
        _fill(kb, 3)
        kb.sync_graph()
        rows = kb.query("SELECT ?pose WHERE { GRAPH ?g { ?o a hiper:Observation ; hiper:poseId ?pose } }")
        assert sorted(int(r["pose"].value) for r in rows) == [0, 0, 1, 1, 2, 2]
    with open_kb(tmp_path / "kb") as kb:  # the detail is a property of the knowledge base
        assert kb.config.observation_detail == "full"


def test_ontology_parses_and_declares_the_classes():
    import pyoxigraph as ox

    triples = list(ox.parse(ontology_turtle(), format=ox.RdfFormat.TURTLE))
    classes = {t.subject.value.rsplit("#", 1)[-1] for t in triples
               if t.object == ox.NamedNode("http://www.w3.org/2002/07/owl#Class")}
    assert {"Observation", "Instance", "Analysis", "Environment", "Session", "Layer"} <= classes
    supers = {(t.subject.value.rsplit("#", 1)[-1], t.object.value) for t in triples
              if t.predicate.value.endswith("subClassOf")}
    assert ("Observation", "http://www.w3.org/ns/sosa/Observation") in supers


def test_read_while_a_writer_holds_the_store(tmp_path):
    from hiper_cli.graph import open_kb_for_reading

    with open_kb(tmp_path / "kb") as writer:
        _fill(writer, 4)
        writer.sync_graph()
        with open_kb_for_reading(tmp_path / "kb") as reader:
            assert reader.read_only
            assert reader.info()["totals"]["observation"] == 8
            assert reader.check(repair=False).ok


def test_spatial_query_equals_brute_force(tmp_path):
    rng = np.random.default_rng(7)
    with open_kb(tmp_path / "kb") as kb:
        env = kb.environment("lab")
        session = kb.start_session(env, "/logs/rand", [])
        expected = {}
        for pose in range(40):
            T = np.eye(4)
            T[:3, 3] = rng.uniform(-5, 5, 3)
            obs = [Observation("foreground", "cup", 0.5, float(pose), pose,
                               Box3D(rng.uniform(-2, 2, 3), rng.uniform(0.05, 3.0, 3)))
                   for _ in range(10)]
            for o in obs:
                expected[o.uuid] = o.box.transformed(T).aabb()
            kb.write_frame(session, FrameResult(obs), pose_id=pose, stamp_s=float(pose), T_map_cam=T)
        for _ in range(30):
            lo = rng.uniform(-8, 8, 3)
            hi = lo + rng.uniform(0.1, 3.0, 3)
            truth = {u for u, (a, b) in expected.items() if np.all(b >= lo) and np.all(a <= hi)}
            found = {d["uuid"] for d in kb.docs.in_box(lo.tolist(), hi.tolist(), type="observation")}
            assert found == truth


def test_an_interrupted_sync_is_repaired_by_the_next(kb_location):
    """The bulk loader is not atomic: a sync killed half-way leaves nodes the mark does not
    cover, possibly of older document versions. The dirty flag makes the next sync replace
    every node it replays."""
    from hiper_cli.graph.ontology import doc_quads

    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        env, _, _ = _fill(kb)
        kb.sync_graph()
        mark = kb.graph.synced_seq(kb.kb_id)
        walker = Instance("foreground", "person", Box3D(np.zeros(3), np.ones(3)), 30.0, 30.0)
        kb.put_documents([walker.to_dict()], env_uuid=env.uuid)
        # a sync starts, writes the walker's node as it is now, and dies before its mark
        kb.graph.begin_sync(kb.kb_id)
        stale = doc_quads(kb.kb_id, kb.docs.get(walker.uuid) | {"env_uuid": env.uuid})
        kb.graph.append_nquads("".join(f"{q} .\n" for q in stale))
        # the writer goes on: the walker moves on before the graph catches up
        walker.last_seen_s, walker.box = 31.0, Box3D(np.full(3, 2.0), np.ones(3))
        kb.put_documents([walker.to_dict()], env_uuid=env.uuid)
        assert kb.graph.sync_state(kb.kb_id) == (mark, True)
    with open_kb(location, docs_dir=docs) as kb:  # the open syncs
        assert kb.graph.sync_state(kb.kb_id) == (kb.docs.seq, False)
        report = kb.check(repair=False)
        assert report.ok, report.problems
        rows = kb.query(f"SELECT ?t WHERE {{ GRAPH ?g {{ <urn:uuid:{walker.uuid}> hiper:lastSeenS ?t }} }}")
        assert [float(r["t"].value) for r in rows] == [31.0]


def test_a_follower_process_keeps_the_graph_up_to_date(kb_location):
    from hiper_cli.graph.follower import GraphFollower

    location, docs = kb_location
    with open_kb(location, docs_dir=docs) as kb:
        env = kb.environment("lab")
        session = kb.start_session(env, "/logs/follow", [])
        with GraphFollower(kb, interval_s=0.05) as follower:
            if docs is None:  # the local store belongs to the follower meanwhile
                with pytest.raises(KnowledgeBaseError, match="graph follower"):
                    kb.query("SELECT * WHERE { ?s ?p ?o } LIMIT 1")
            cup = Instance("foreground", "cup", Box3D(np.zeros(3), np.ones(3)), 0.0, 0.0)
            for pose in range(40):
                obs = Observation("foreground", "cup", 0.5, float(pose), pose, Box3D(np.zeros(3), np.ones(3)),
                                  instance_uuid=cup.uuid)
                cup.observation_uuids.append(obs.uuid)
                cup.last_seen_s = float(pose)
                kb.write_frame(session, FrameResult([obs], [cup]), pose_id=pose, stamp_s=float(pose),
                               T_map_cam=np.eye(4))
        report = follower.report
        assert report.syncs >= 1 and report.documents >= 1 and report.links >= 1 and not report.errors
        assert report.peak_rss_mb > 0 and report.cpu_s > 0
        assert kb.graph.synced_seq(kb.kb_id) == kb.docs.seq
        assert kb.check(repair=False).ok
        g = layer_graph(kb.kb_id, "foreground")  # the endpoint may hold other tests' graphs
        rows = kb.query(f"SELECT (SUM(?k) AS ?n) WHERE {{ GRAPH {g} {{ ?b a hiper:ObservationBatch ; "
                        "hiper:observationCount ?k } }")
        assert int(rows[0]["n"].value) == 40


def test_small_syncs_are_not_flushed_yet_readers_see_them(tmp_path, monkeypatch):
    """A store flush costs ~70 ms whatever its size: a sync after each frame leaves its quads in
    the write-ahead log, which a reader opening the store sees; a large catch-up flushes."""
    from hiper_cli.graph import sync as graph_sync
    from hiper_cli.graph.scenegraph import LocalGraph

    location = tmp_path / "scene.hiper"
    with open_kb(str(location)) as kb:
        env, _, _ = _fill(kb)
        kb.sync_graph()
        buffered = kb.graph.buffered_quads()
        assert buffered > 0  # the catch-up was small: nothing flushed
        reader = LocalGraph(location / "graph", read_only=True)
        try:
            assert reader.synced_seq(kb.kb_id) == kb.docs.seq
            counts = {r["t"].value: int(r["n"].value) for r in reader.query(
                "SELECT ?t (COUNT(?s) AS ?n) WHERE { GRAPH ?g { ?s a ?t } } GROUP BY ?t")}
            assert counts and sum(counts.values()) >= kb.docs.count(type="instance")
        finally:
            reader.close()
        monkeypatch.setattr(graph_sync, "FLUSH_MIN_QUADS", buffered + 1)
        cup = Instance("foreground", "cup", Box3D(np.zeros(3), np.ones(3)), 40.0, 40.0)
        kb.put_documents([cup.to_dict()], env_uuid=env.uuid)
        kb.sync_graph()  # past the threshold now
        assert kb.graph.buffered_quads() == 0
