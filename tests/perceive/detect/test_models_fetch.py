"""hiper models: download from a local HTTP server, resume, verify, refuse, add, list."""

import hashlib
import json
import re
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError, DownloadError
from hiper_cli.perceive.detect.catalog import ModelEntry, entry, find_model, locate, models_dir
from hiper_cli.perceive.detect.fetch import add_model, fetch_model

PAYLOAD = bytes(range(256)) * 400  # 102400 bytes
SHA = hashlib.sha256(PAYLOAD).hexdigest()
SHARED_YOLOX = locate("yolox_nano")  # HIPER_MODELS, the user cache or shared/models above the repository


class _Server:
    """Serves ``body`` at any path; honours Range unless ``ranges`` is False; with ``cut`` it
    announces the whole length but closes after ``cut`` bytes (a dropped connection)."""

    def __init__(self, body: bytes) -> None:
        self.body, self.ranges, self.cut = body, True, None
        self.requests: list[str | None] = []
        server = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                server.requests.append(self.headers.get("Range"))
                start = 0
                rng = self.headers.get("Range")
                if rng and server.ranges:
                    start = int(re.match(r"bytes=(\d+)-", rng).group(1))
                    if start >= len(server.body):
                        self.send_response(416)
                        self.end_headers()
                        return
                    self.send_response(206)
                else:
                    self.send_response(200)
                rest = server.body[start:]
                self.send_header("Content-Length", str(len(rest)))
                self.end_headers()
                self.wfile.write(rest if server.cut is None else rest[: server.cut])

            def log_message(self, *args: object) -> None:
                pass

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}/model.onnx"
        threading.Thread(target=self.httpd.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def server():
    s = _Server(PAYLOAD)
    yield s
    s.close()


@pytest.fixture(autouse=True)
def _isolated_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("HIPER_MODELS", raising=False)


def _entry(sha=SHA):
    return ModelEntry(
        "tiny_test", "yolox", 416, "test", None, url="https://example.invalid/x.onnx", sha256=sha
    )


def _files(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def test_fetch_downloads_verifies_and_renames(server, tmp_path):
    seen = []
    result = fetch_model(_entry(), tmp_path, url=server.url, progress=lambda d, t: seen.append((d, t)))
    assert result.path == tmp_path / "tiny_test" / "tiny_test.onnx"
    assert result.path.read_bytes() == PAYLOAD and result.sha256 == SHA and result.verified
    assert _files(tmp_path) == ["tiny_test/tiny_test.onnx"]
    assert seen[-1] == (len(PAYLOAD), len(PAYLOAD))
    # a second fetch finds the verified file and downloads nothing
    again = fetch_model(_entry(), tmp_path, url=server.url)
    assert again.downloaded_bytes == 0 and len(server.requests) == 1


def test_wrong_checksum_is_refused_and_nothing_stays(server, tmp_path):
    with pytest.raises(DownloadError, match=r"sha256 [0-9a-f]{64} is not the known tiny_test \(0{64}\)"):
        fetch_model(_entry("0" * 64), tmp_path, url=server.url)
    assert _files(tmp_path) == []


def test_an_interrupted_download_resumes_with_a_range_request(server, tmp_path):
    server.cut = 40000
    with pytest.raises(
        DownloadError, match=r"stopped after 40000 of 102400 bytes.*run the same command again to resume"
    ):
        fetch_model(_entry(), tmp_path, url=server.url)
    assert _files(tmp_path) == ["tiny_test/tiny_test.onnx.part"]  # never under the model's name
    server.cut = None
    result = fetch_model(_entry(), tmp_path, url=server.url)
    assert server.requests == [None, "bytes=40000-"]
    assert result.resumed_from == 40000 and result.downloaded_bytes == len(PAYLOAD) - 40000
    assert result.path.read_bytes() == PAYLOAD and _files(tmp_path) == ["tiny_test/tiny_test.onnx"]


def test_a_server_without_ranges_restarts_from_zero(server, tmp_path):
    part = tmp_path / "tiny_test" / "tiny_test.onnx.part"
    part.parent.mkdir()
    part.write_bytes(b"junk" * 1000)
    server.ranges = False
    result = fetch_model(_entry(), tmp_path, url=server.url)
    assert server.requests == ["bytes=4000-"] and result.resumed_from == 0
    assert result.path.read_bytes() == PAYLOAD


def test_a_whole_part_is_verified_without_downloading_again(server, tmp_path):
    part = tmp_path / "tiny_test" / "tiny_test.onnx.part"
    part.parent.mkdir()
    part.write_bytes(PAYLOAD)
    result = fetch_model(_entry(), tmp_path, url=server.url)
    assert server.requests == [f"bytes={len(PAYLOAD)}-"] and result.downloaded_bytes == 0 and result.verified


def test_offline_is_one_line_naming_the_url_and_the_manual_step(tmp_path):
    import socket

    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"http://127.0.0.1:{port}/yolox_nano.onnx"
    with pytest.raises(DownloadError) as err:
        fetch_model(_entry(), tmp_path, url=url, timeout_s=5)
    message = str(err.value)
    assert "\n" not in message and url in message and "hiper models add FILE" in message
    assert _files(tmp_path) == []


def test_unknown_sha256_needs_an_explicit_flag(server, tmp_path):
    with pytest.raises(ConfigError, match=r"no verified sha256 is known.*--trust-unverified"):
        fetch_model(_entry(None), tmp_path, url=server.url)
    assert _files(tmp_path) == []
    result = fetch_model(_entry(None), tmp_path, url=server.url, allow_unverified=True)
    assert result.sha256 == SHA and not result.verified


def test_models_without_a_published_onnx_say_how_to_export():
    with pytest.raises(ConfigError, match=r"publish no ONNX file; export one \(pip install ultralytics"):
        fetch_model(entry("yolo11n"), Path("/nonexistent"))
    assert entry("yolox").name == "yolox_nano"
    with pytest.raises(ConfigError, match=r"unknown model 'yolo9'; expected one of yolox_nano, "):
        entry("yolo9")


def test_add_checks_a_known_sha256(tmp_path):
    wrong = tmp_path / "yolox_nano.onnx"
    wrong.write_bytes(PAYLOAD)
    with pytest.raises(DownloadError, match=r"is not the known yolox_nano"):
        add_model(entry("yolox_nano"), wrong, tmp_path / "models")
    assert not (tmp_path / "models").exists() or _files(tmp_path / "models") == []


def test_the_cache_is_where_fetched_models_go_and_are_found(tmp_path, monkeypatch):
    assert models_dir() == tmp_path / "cache" / "hiper" / "models"
    assert locate("yolox", roots=[]) is None
    with pytest.raises(
        ConfigError, match=r"not found in .*cache/hiper/models.*hiper models fetch yolox_nano"
    ):
        find_model("yolox", roots=[])
    target = models_dir() / "yolox_nano" / "yolox_nano.onnx"
    target.parent.mkdir(parents=True)
    target.write_bytes(b"x")
    assert locate("yolox", roots=[]) == target
    monkeypatch.setenv("HIPER_MODELS", str(tmp_path / "elsewhere"))  # the cache is still searched
    assert models_dir() == tmp_path / "elsewhere" and locate("yolox", roots=[]) == target


def _shared_model() -> Path:
    if SHARED_YOLOX is None:
        pytest.skip("the YOLOX-Nano file is absent (set HIPER_MODELS; see docs/foreground.md)")
    return SHARED_YOLOX


def test_cli_fetch_from_a_mirror_then_the_detector_finds_it(tmp_path):
    mirror = _Server(_shared_model().read_bytes())
    try:
        folder = tmp_path / "models"
        result = CliRunner().invoke(
            app, ["models", "fetch", "yolox", "--from", mirror.url, "--dir", str(folder), "--json"]
        )
        assert result.exit_code == 0, result.output
        data = json.loads(result.stdout)
        assert data["verified"] and data["path"] == str(folder / "yolox_nano" / "yolox_nano.onnx")
        assert data["sha256"] == entry("yolox").sha256
        from hiper_cli.perceive.detect.yolox import find_yolox_model

        assert locate("yolox", roots=[]) is None  # --dir is not the cache...
        target = models_dir() / "yolox_nano"
        target.mkdir(parents=True)
        (target / "yolox_nano.onnx").write_bytes(Path(data["path"]).read_bytes())
        assert find_yolox_model(search_roots=[]) == target / "yolox_nano.onnx"  # ...the cache is
    finally:
        mirror.close()


def test_cli_fetch_refuses_a_mirror_with_another_file(server, tmp_path):
    folder = tmp_path / "models"
    result = CliRunner().invoke(app, ["models", "fetch", "yolox", "--from", server.url, "--dir", str(folder)])
    assert result.exit_code == 1
    assert re.search(r"error: .*sha256 [0-9a-f]{64} is not the known yolox_nano", result.output)
    assert _files(folder) == []


def test_cli_list_and_add(tmp_path):
    model = _shared_model()
    folder = tmp_path / "models"
    result = CliRunner().invoke(app, ["models", "add", str(model), "--dir", str(folder), "--json"])
    assert result.exit_code == 0, result.output
    added = json.loads(result.stdout)
    assert added["layout"] == "yolox" and added["classes"] == 80 and added["verified"]
    listed = json.loads(CliRunner().invoke(app, ["models", "list", "--dir", str(folder), "--json"]).stdout)
    rows = {r["name"]: r for r in listed["models"]}
    assert rows["yolox_nano"]["path"] == added["path"] and rows["yolox_s"]["sha256"] is None
    assert rows["yolox_s"]["url"].startswith("https://github.com/Megvii-BaseDetection/YOLOX/releases/")
