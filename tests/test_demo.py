"""``make demo`` on a fresh machine: with no model and no network it says so in one line, falls
back to the log's simulated detections and exits 0; with YOLOX-Nano in the user cache (what one
``hiper models fetch yolox`` leaves) it uses ``yolox``. Run in a copy of the repository, so that
no ``shared/models`` above it is found."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from hiper_cli.perceive.detect.catalog import locate

ROOT = Path(__file__).resolve().parents[1]
URL = "https://github.com/Megvii-BaseDetection/YOLOX/releases/download/0.1.1rc0/yolox_nano.onnx"


def _fresh_copy(tmp: Path) -> tuple[Path, Path]:
    """A copy of the code, scripts and example log, and a 'venv' whose hiper runs that code."""
    repo = tmp / "repo"
    repo.mkdir()
    shutil.copytree(ROOT / "hiper_cli", repo / "hiper_cli", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "scripts", repo / "scripts")
    (repo / "fixtures").symlink_to(ROOT / "fixtures")
    venv = tmp / "venv" / "bin"
    venv.mkdir(parents=True)
    for name, cmd in (
        ("python", f'exec {sys.executable} "$@"'),
        ("hiper", f'exec {sys.executable} -m hiper_cli "$@"'),
    ):
        (venv / name).write_text(f"#!/bin/sh\n{cmd}\n")
        (venv / name).chmod(0o755)
    return repo, venv.parent


def _run_demo(tmp: Path, with_model: bool) -> tuple[subprocess.CompletedProcess[str], Path]:
    repo, venv = _fresh_copy(tmp)
    cache = tmp / "cache"
    if with_model:
        model = locate("yolox_nano")
        if model is None:
            pytest.skip("YOLOX-Nano model absent (run 'hiper models fetch yolox' or set HIPER_MODELS)")
        (cache / "hiper" / "models" / "yolox_nano").mkdir(parents=True)
        shutil.copy(model, cache / "hiper" / "models" / "yolox_nano" / "yolox_nano.onnx")
    env = {k: v for k, v in os.environ.items() if k not in ("HIPER_MODELS", "PYTHONPATH")}
    # No network: every HTTPS request goes to a proxy port nobody listens on.
    env |= {
        "PYTHONPATH": str(repo),
        "XDG_CACHE_HOME": str(cache),
        "https_proxy": "http://127.0.0.1:9",
        "HTTPS_PROXY": "http://127.0.0.1:9",
    }
    done = subprocess.run(
        ["bash", "scripts/demo.sh", str(venv)], cwd=repo, env=env, capture_output=True, text=True, timeout=300
    )
    return done, repo


@pytest.mark.slow
def test_offline_demo_says_so_in_one_line_and_falls_back(tmp_path):
    done, repo = _run_demo(tmp_path, with_model=False)
    assert done.returncode == 0, done.stderr[-2000:]
    said = [line for line in done.stdout.splitlines() if line.startswith("demo: detector")]
    assert len(said) == 1 and said[0].startswith("demo: detector 'truth'")
    assert URL in said[0] and "hiper models add FILE" in said[0]
    assert "demo: done with detector 'truth'" in done.stdout
    assert (repo / "out" / "demo.png").is_file() and not list((tmp_path / "cache").rglob("*.part"))


@pytest.mark.slow
def test_demo_uses_yolox_once_it_is_in_the_cache(tmp_path):
    done, repo = _run_demo(tmp_path, with_model=True)
    assert done.returncode == 0, done.stderr[-2000:]
    said = [line for line in done.stdout.splitlines() if line.startswith("demo: detector")]
    assert said == [
        f"demo: detector 'yolox' (YOLOX-Nano at {tmp_path}/cache/hiper/models/yolox_nano/yolox_nano.onnx)"
    ]
    assert "--detector yolox" in done.stderr  # the perceive command, as set -x shows it
    assert (repo / "out" / "demo.png").is_file()


def test_the_readme_picture_is_the_demo_s_and_says_which_detector():
    """The README's picture block is the one scripts/readme_image.sh rewrites from a demo run."""
    readme = (ROOT / "README.md").read_text()
    script = (ROOT / "scripts" / "readme_image.sh").read_text()
    block = readme.split("<!-- demo-image -->\n", 1)[1].split("<!-- /demo-image -->", 1)[0]
    assert "scripts/readme_image.sh" in block and re.search(r"detector `(yolox|truth)`", block)
    image = re.search(r"!\[[^\]]*\]\((docs/images/[^)]+\.png)\)", readme.split("<!-- /demo-image -->", 1)[1])
    assert image and f"cp out/demo.png {image.group(1)}" in script and (ROOT / image.group(1)).is_file()
