"""``hiper query``, ``hiper describe``, ``hiper serve``: --json against the documented schema,
read-only SPARQL, errors as one line, injection attempts, an external SPARQL client."""

from __future__ import annotations

import json
import subprocess
import sys
from importlib import resources

import jsonschema
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import QueryError
from hiper_cli.graph import open_kb
from hiper_cli.query import ask
from hiper_cli.query.bench import QUERY_FORMS
from hiper_cli.query.templates import template
from tests import REPO_ROOT
from tests.query_truth_kb import house_truth_kb

runner = CliRunner()
EXAMPLES = (
    *QUERY_FORMS,  # the examples, the benchmark's query forms
    "is there a cup on the table",
    "go to the couch",
    "how long was the person in view",
    "chairs within 2 m of me",
    "mugs near the table",
)
COUNT_QUERY = """SELECT ?class (COUNT(?i) AS ?n) WHERE { GRAPH ?g { ?i a hiper:Instance ;
  hiper:className ?class } } GROUP BY ?class ORDER BY ?class"""


@pytest.fixture(scope="module")
def kb_path(house_kb_path: str) -> str:
    return house_kb_path


def _schema():
    text = resources.files("hiper_cli.query").joinpath("answer.schema.json").read_text()
    return json.loads(text)


def _quads(kb_path: str) -> int:
    with open_kb(kb_path) as kb:
        return int(kb.query("SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }")[0]["n"].value)


@pytest.mark.parametrize("words", EXAMPLES)
def test_json_answers_validate_against_the_schema(kb_path, words):
    result = runner.invoke(app, ["query", words, "--kb", kb_path, "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    jsonschema.validate(data, _schema())
    assert data["query"] == words and data["version"] == 1


def test_schema_rejects_a_broken_answer(kb_path):
    data = json.loads(runner.invoke(app, ["query", "closest chair", "--kb", kb_path, "--json"]).output)
    data["hits"][0]["position_m"] = [1.0, 2.0]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(data, _schema())


def test_table_output_and_one_line_errors(kb_path):
    result = runner.invoke(app, ["query", "how many chairs", "--kb", kb_path])
    assert result.exit_code == 0 and "chair" in result.output
    bad = runner.invoke(app, ["query", "cupz in the kitchen", "--kb", kb_path])
    assert bad.exit_code == 1
    text = " ".join(bad.output.split())
    assert '"cupz"' in text and '"kitchen"' in text and "did you mean" in text and "in FOV" in text
    assert "Traceback" not in bad.output


def test_the_table_holds_one_line_per_hit_in_80_columns(kb_path):
    hits = json.loads(runner.invoke(app, ["query", "objects", "--kb", kb_path, "--json"]).output)["hits"]
    table = runner.invoke(app, ["query", "objects", "--kb", kb_path], env={"COLUMNS": "80"}).output
    lines = table.splitlines()
    header = next(k for k, line in enumerate(lines) if line.startswith("class "))
    rows = [line for line in lines[header + 1 :] if line.strip()]
    assert len(rows) == len(hits)
    for row, hit in zip(rows, hits, strict=True):
        tail = hit["uuid"].replace("-", "")[-8:]  # a uuid7 begins with the time: the tail tells apart
        assert row.startswith(hit["class"]) and tail in row and hit["state"] in row
    assert len({hit["uuid"][-8:] for hit in hits}) == len(hits)


def test_pose_and_at_options(kb_path):
    far = runner.invoke(
        app, ["query", "chairs within 1 m of me", "--kb", kb_path, "--pose", "-50,-50,1.2,0", "--json"]
    )
    assert json.loads(far.output)["hits"] == []
    assert json.loads(far.output)["reference"]["source"] == "given"
    bad = runner.invoke(app, ["query", "closest chair", "--kb", kb_path, "--pose", "1,2"])
    assert bad.exit_code == 1 and "x,y,z,yaw" in bad.output.replace("\n", "")
    early = json.loads(
        runner.invoke(app, ["query", "how many chairs", "--kb", kb_path, "--at", "0.5", "--json"]).output
    )
    late = json.loads(runner.invoke(app, ["query", "how many chairs", "--kb", kb_path, "--json"]).output)
    assert early["now"]["stamp_s"] == 0.5 and early["count"] < late["count"]


def test_sparql_file_and_stdin_are_read_only(kb_path, tmp_path):
    rq = tmp_path / "count.rq"
    rq.write_text(COUNT_QUERY)
    result = runner.invoke(app, ["query", "--sparql", str(rq), "--kb", kb_path, "--json"])
    assert result.exit_code == 0, result.output
    rows = json.loads(result.output)["results"]["bindings"]
    counts = {r["class"]["value"]: int(r["n"]["value"]) for r in rows}
    assert counts["chair"] == ask_count(kb_path, "how many chairs")
    stdin = runner.invoke(app, ["query", "--sparql", "-", "--kb", kb_path, "--json"], input=COUNT_QUERY)
    assert json.loads(stdin.output) == json.loads(result.output)
    inline = runner.invoke(app, ["query", "--sparql", COUNT_QUERY, "--kb", kb_path, "--json"])
    assert json.loads(inline.output) == json.loads(result.output)
    long_query = COUNT_QUERY.replace("SELECT", "SELECT" + " " * 300)  # longer than a file name may be
    inline = runner.invoke(app, ["query", "--sparql", long_query, "--kb", kb_path, "--json"])
    assert json.loads(inline.output) == json.loads(result.output)
    missing = runner.invoke(app, ["query", "--sparql", str(tmp_path / "none.rq"), "--kb", kb_path])
    assert missing.exit_code == 1
    assert "none.rq: cannot read the SPARQL file" in " ".join(missing.output.split())
    flag_only = runner.invoke(app, ["query", COUNT_QUERY, "--sparql", "--kb", kb_path])  # the query before it
    assert flag_only.exit_code == 1 and "right after --sparql" in " ".join(flag_only.output.split())
    before = _quads(kb_path)
    for update in (
        "INSERT DATA { GRAPH <urn:x> { <urn:a> <urn:b> <urn:c> } }",
        "DROP ALL",
        "DELETE WHERE { GRAPH ?g { ?s ?p ?o } }",
        "CLEAR ALL",
    ):
        refused = runner.invoke(app, ["query", "--sparql", "-", "--kb", kb_path], input=update)
        assert refused.exit_code == 1 and "refused" in refused.output
        inline = runner.invoke(app, ["query", "--sparql", update, "--kb", kb_path])
        assert inline.exit_code == 1 and "refused" in inline.output
    assert _quads(kb_path) == before


def ask_count(kb_path: str, words: str) -> int:
    with open_kb(kb_path) as kb:
        count = ask(kb, words).count
    assert count is not None
    return count


INJECTIONS = [
    'cup" } INSERT DATA { GRAPH <urn:x> { <urn:a> <urn:b> <urn:c> } } #',
    "cup' } DROP ALL #",
    'cup"@en . } } DELETE WHERE { ?s ?p ?o } #',
    "}}} UNION { ?i ?p ?o }",
    'cup\\" }',
    "cup\n} DROP ALL",
]


@pytest.mark.parametrize("value", INJECTIONS)
def test_bound_values_cannot_change_a_query(kb_path, value):
    before = _quads(kb_path)
    with open_kb(kb_path) as kb:
        bindings = {"graphPrefix": f"urn:hiper:kb:{kb.kb_id}:", "class": value}
        assert kb.query_bound(template("instances"), bindings) == []
        # the endpoint form of a binding: a VALUES row of serialised terms, run on the local store
        from hiper_cli.graph.scenegraph import values_bound

        assert kb.query(values_bound(template("instances"), bindings)) == []
        with pytest.raises(QueryError, match="cannot read"):
            ask(kb, f"{value} in FOV")
    assert _quads(kb_path) == before


def test_iris_with_brackets_are_refused_as_values(kb_path):
    import pyoxigraph as ox

    with pytest.raises(ValueError):
        ox.NamedNode("urn:uuid:x> } DROP ALL #")
    with open_kb(kb_path) as kb:
        assert kb.query_bound(template("instance"), {"i": "urn:uuid:x> } DROP ALL #"}) == []


def test_serve_answers_an_external_client_like_query_sparql(kb_path):
    from rdflib.plugins.stores.sparqlstore import SPARQLStore

    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.serve import SparqlEndpoint

    prefixed = "PREFIX hiper: <https://w3id.org/hiper#>\n" + COUNT_QUERY
    cli = json.loads(
        runner.invoke(app, ["query", "--sparql", "-", "--kb", kb_path, "--json"], input=COUNT_QUERY).output
    )
    expected = [(r["class"]["value"], int(r["n"]["value"])) for r in cli["results"]["bindings"]]
    with open_kb_for_reading(kb_path) as kb, SparqlEndpoint(kb, "127.0.0.1", 0) as endpoint:
        assert endpoint.url.startswith("http://127.0.0.1:")
        for method in ("GET", "POST"):
            store = SPARQLStore(endpoint.url, method=method, returnFormat="json")
            rows = [(str(r[0]), int(r[1])) for r in store.query(prefixed)]
            assert rows == expected
        xml = SPARQLStore(endpoint.url, returnFormat="xml")
        assert [(str(r[0]), int(r[1])) for r in xml.query(prefixed)] == expected
        import urllib.error
        import urllib.parse
        import urllib.request

        url = endpoint.url + "?" + urllib.parse.urlencode({"query": prefixed})
        with urllib.request.urlopen(urllib.request.Request(url, headers={"Accept": "text/csv"})) as response:
            csv_rows = response.read().decode().splitlines()
        assert csv_rows[0] == "class,n" and len(csv_rows) == len(expected) + 1
        for body, ctype in (
            ("DROP ALL", "application/sparql-update"),
            ("update=DROP%20ALL", "application/x-www-form-urlencoded"),
        ):
            request = urllib.request.Request(
                endpoint.url, data=body.encode(), method="POST", headers={"Content-Type": ctype}
            )
            with pytest.raises(urllib.error.HTTPError) as err:
                urllib.request.urlopen(request)
            assert err.value.code == 403
        refused = urllib.parse.urlencode({"query": "INSERT DATA { <urn:a> <urn:b> <urn:c> }"})
        with pytest.raises(urllib.error.HTTPError) as err:
            urllib.request.urlopen(endpoint.url + "?" + refused)
        assert err.value.code == 403


def test_describe_summarises_counts_and_says_what_is_missing(kb_path):
    result = runner.invoke(app, ["describe", "--kb", kb_path, "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    chairs = [c for c in data["classes"] if c["class"] == "chair"]
    assert chairs and chairs[0]["count"] == ask_count(kb_path, "how many chairs")
    assert "person" in {m["class"] for m in data["recent_movers"]} or data["recent_movers"] == []
    assert "Learned features: none" in data["text"] and len(data["text"]) < 2000
    text = runner.invoke(app, ["describe", "--kb", kb_path])
    assert "Foreground:" in text.output


def test_workspace_around_a_table(kb_path):
    h = house_truth_kb()
    (table,) = [t for t, ti in h.truth.instances.items() if ti.name == "table_0"]
    c = h.truth.instances[table].box.center_m
    result = runner.invoke(
        app,
        [
            "query",
            "workspace",
            "--center",
            f"{c[0]},{c[1]},0.8",
            "--size",
            "2.0",
            "--resolution",
            "0.05",
            "--kb",
            kb_path,
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert "table" in {p["class"] for p in data["background"]}
    classes = data["foreground"]["classes"]
    assert {"cup", "bottle"} <= set(classes)
    cup = classes.index("cup")
    assert any(v[3] == cup for v in data["foreground"]["occupied"])
    assert data["foreground"]["dynamics"]["cup"]["source"] == "instances"
    bad = runner.invoke(app, ["query", "workspace", "--center", "1,2", "--kb", kb_path])
    assert bad.exit_code == 1


def test_query_help_imports_no_heavy_module():
    code = (
        "import sys; sys.argv = ['hiper', 'query', '--help']\n"
        "from hiper_cli.cli import main\n"
        "try:\n    main()\nexcept SystemExit:\n    pass\n"
        "heavy = {'numpy', 'pyoxigraph', 'rdflib', 'scipy', 'open3d', 'cv2', 'sqlite3', 'jsonschema'}\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in heavy), file=sys.stderr)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "Example:" in done.stdout
    assert done.stderr.strip() == "[]"


@pytest.mark.slow
def test_the_wheel_ships_the_named_queries_and_the_schema(tmp_path):
    import zipfile

    root = REPO_ROOT
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(root)],
                   check=True, capture_output=True)
    (wheel,) = tmp_path.glob("hiper-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    shipped = {p.name for p in (root / "queries").glob("*.rq")}
    assert shipped and {f"hiper_cli/queries/{n}" for n in shipped} <= names
    assert "hiper_cli/query/answer.schema.json" in names


def test_describe_and_workspace_read_learned_features(tmp_path):
    import shutil

    from hiper_cli.model import Analysis
    from hiper_cli.query.describe import describe
    from hiper_cli.query.workspace import workspace

    h = house_truth_kb()
    shutil.copytree(h.path, tmp_path / "kb.hiper")
    ods = {"mean_mps": 0.8, "cl_mps": 0.7, "cu_mps": 0.9, "ratio": 0.4, "sigma_mps": 0.1}
    with open_kb(tmp_path / "kb.hiper") as kb:
        kb.put_analyses([Analysis("ods", "person", 0.0, 40.0, ods, 1.0)])
        kb.sync_graph()
        summary = describe(kb)
        assert summary.features[0]["kind"] == "ods" and summary.features[0]["values"] == ods
        assert "ods person:" in summary.text and "mean_mps 0.8" in summary.text
        person = ask(kb, "where was the person last seen").hits[0]
        ws = workspace(kb, person.center_map_m, 3.0, resolution_m=0.1)
        assert ws.dynamics["person"]["source"] == "ods" and ws.dynamics["person"]["mean_mps"] == 0.8


def test_every_example_answers_on_a_perceived_house_log(tmp_path):
    """The fixture house log through the real pipeline (truth detector): every example query
    answers without error and validates; counts agree with the instances the KB holds."""

    from hiper_cli.pipeline import PerceiveOptions, perceive_log

    log = REPO_ROOT / "fixtures" / "house_small"
    perceive_log(log, str(tmp_path / "kb.hiper"),
                 options=PerceiveOptions(stage_options={"foreground": {"detector": "truth"}}))
    with open_kb(tmp_path / "kb.hiper") as kb:
        for words in EXAMPLES:
            jsonschema.validate(ask(kb, words).to_dict(), _schema())
        people = len(kb.instances(class_name="person"))
        assert ask(kb, "how many people").count == people
        walls = ask(kb, "closest wall")
        assert walls.hits and walls.hits[0].class_name == "wall" and walls.goal is not None
