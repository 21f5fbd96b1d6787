"""The library functions behind ``hiper query`` and ``hiper analyze``: the CLI only prints what
they return, so Python callers get the same answers (and the same one-line errors)."""

import io
import json

import pytest
from typer.testing import CliRunner

from hiper_cli.analyze.requests import WindowText, features_at, map_at
from hiper_cli.cli import app
from hiper_cli.errors import ConfigError, QueryError
from hiper_cli.model import json_default
from hiper_cli.query.request import parse_floats, parse_stamp, run_query, sparql_source
from hiper_cli.query.views import query_view
from tests.kb_helpers import small_kb

runner = CliRunner()
COUNT = "SELECT (COUNT(?i) AS ?n) WHERE { GRAPH ?g { ?i a hiper:Instance } }"


@pytest.fixture(scope="module")
def kb_path(tmp_path_factory):
    root = tmp_path_factory.mktemp("request") / "flat.hiper"
    small_kb(root).close()
    return str(root)


def _cli(*args: str) -> dict:
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.output)


def _plain(data: dict) -> dict:
    return json.loads(json.dumps(data, default=json_default))


def test_words_and_sparql_answer_as_the_cli_does(kb_path):
    answer = run_query(kb_path, ["closest", "chair"], pose="0,0,0,0")
    assert _plain(answer.to_dict()) == _cli("query", "closest chair", "--kb", kb_path, "--pose", "0,0,0,0")
    assert answer.hits[0].class_name == "chair" and query_view(answer).rows[0][0] == "chair"
    sparql = run_query(kb_path, sparql=COUNT)
    assert _plain(sparql.to_dict()) == _cli("query", "--sparql", COUNT, "--kb", kb_path)
    assert query_view(sparql).rows == [["3"]]


def test_the_text_options_are_checked_with_one_line_errors():
    assert parse_floats("1,2,0.5", 3, "--center", "x,y,z (m)") == (1.0, 2.0, 0.5)
    with pytest.raises(QueryError, match=r"--pose '1,2': expected 4 comma-separated finite numbers"):
        parse_floats("1,2", 4, "--pose", "x,y,z,yaw")
    assert parse_stamp("12.5", "--at", 0.0) == 12.5
    with pytest.raises(QueryError, match=r"--now 'noon-ish': expected a stamp in seconds"):
        parse_stamp("noon-ish", "--now", 0.0)


def test_a_sparql_source_is_a_query_a_file_or_stdin(tmp_path):
    rq = tmp_path / "count.rq"
    rq.write_text(COUNT)
    assert sparql_source(COUNT, io.StringIO()) == sparql_source(str(rq), io.StringIO()) == COUNT
    assert sparql_source("-", io.StringIO(COUNT)) == COUNT
    with pytest.raises(QueryError, match="right after --sparql"):
        sparql_source("--kb", io.StringIO())
    with pytest.raises(QueryError, match="update"):
        sparql_source("DELETE WHERE { ?s ?p ?o }", io.StringIO())


def test_the_analyses_return_what_the_cli_prints(kb_path, tmp_path):
    run = features_at(kb_path, ["person"], WindowText(), store=False)
    data = _cli("analyze", "features", "--class", "person", "--no-store", "--kb", kb_path)
    classes = [c["class"] for c in run.to_dict()["classes"]]
    assert classes == [c["class"] for c in data["classes"]] == ["person"]
    assert run.to_dict()["stored"] == data["stored"] == 0
    assert run.view()[0].rows[0][:3] == ["person", "1", "3"]  # one track of three rows
    with pytest.raises(ConfigError, match="--last counts back"):
        features_at(kb_path, None, WindowText(t_from="0", last="1h"), store=False)
    built = map_at(kb_path, tmp_path / "map.yaml")
    assert built.to_dict()["yaml"].endswith("map.yaml") and built.view()[0].startswith("map ")
