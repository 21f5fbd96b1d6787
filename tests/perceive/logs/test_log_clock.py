"""Times print as the log's own clock: seconds of log time for a simulated log (never a date in
1970), ISO 8601 UTC for a wall-clock log, and no date before the log's first stamp in any output
of describe, query, view and export."""

from __future__ import annotations

import json
import re
import shutil
from datetime import UTC, datetime
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.clock import is_wall_clock, iso_utc, span_text, stamp_text
from hiper_cli.pipeline import PerceiveOptions, perceive_log
from tests import REPO_ROOT

ROOT = REPO_ROOT
LOG = ROOT / "fixtures" / "house_small"
TRUTH = PerceiveOptions(
    stages=("background", "foreground"), stage_options={"foreground": {"detector": "truth"}}
)
T0_S = 1_700_000_000.0  # 2023-11-14T22:13:20Z
ISO = re.compile(r"(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}(?:\.\d+)?)(Z|[+-]\d{2}:\d{2})?")
runner = CliRunner()


def test_the_clock_of_a_stamp():
    assert not is_wall_clock(14.75) and is_wall_clock(T0_S)
    assert iso_utc(14.75) is None and stamp_text(14.75) == "14.750 s"
    assert stamp_text(T0_S + 0.25) == "2023-11-14T22:13:20.250Z"
    assert span_text(0.0, 14.75) == "t 0.00-14.75 s"
    assert span_text(T0_S, T0_S + 40.25) == "2023-11-14T22:13:20.000Z + 40.25 s"


def _shifted_log(dst: Path) -> Path:
    """The example log with every stamp moved to wall-clock time (T0_S + stamp)."""
    dst.mkdir()
    for name in ("rgb", "depth"):
        (dst / name).symlink_to(LOG / name)
    shutil.copy(LOG / "camera.json", dst / "camera.json")
    for name in ("rgb.txt", "depth.txt", "groundtruth.txt"):
        lines = []
        for line in (LOG / name).read_text().splitlines():
            if line.startswith("#") or not line.strip():
                lines.append(line)
                continue
            stamp, rest = line.split(" ", 1)
            lines.append(f"{T0_S + float(stamp):.6f} {rest}")
        (dst / name).write_text("\n".join(lines) + "\n")
    shutil.copytree(LOG / "gt", dst / "gt")
    records = [json.loads(x) for x in (LOG / "gt" / "detections.jsonl").read_text().splitlines() if x.strip()]
    for r in records:
        r["stamp_s"] += T0_S
    (dst / "gt" / "detections.jsonl").write_text("\n".join(json.dumps(r) for r in records) + "\n")
    return dst


@pytest.fixture(scope="module")
def kbs(tmp_path_factory) -> dict[str, tuple[Path, float]]:
    """kind -> (knowledge base, the log's first stamp)."""
    base = tmp_path_factory.mktemp("clock")
    sim = base / "sim.hiper"
    perceive_log(LOG, str(sim), options=TRUTH)
    wall = base / "wall.hiper"
    perceive_log(_shifted_log(base / "wall_log"), str(wall), options=TRUTH)
    return {"sim": (sim, 0.0), "wall": (wall, T0_S)}


def _outputs(kb: Path, tmp: Path) -> str:
    """Everything describe, query, view and export print or write, text and JSON."""
    out = []
    commands = [["describe"], ["describe", "--json"]]
    for question in (
        "chairs",
        "when was the person last seen",
        "moving people",
        "how many chairs",
        "closest table",
    ):
        commands += [["query", question], ["query", question, "--json"]]
    commands += [
        ["view", "--png", str(tmp / "v.png")],
        ["view", "--png", str(tmp / "v.png"), "--json"],
        ["export", str(tmp / "e.json")],
    ]
    for args in commands:
        result = runner.invoke(app, [*args, "--kb", str(kb)])
        assert result.exit_code == 0, (args, result.output)
        out.append(result.output)
    out.append((tmp / "e.json").read_text())
    return "\n".join(out)


def test_a_simulated_log_prints_log_time_never_a_date(kbs, tmp_path):
    kb, _ = kbs["sim"]
    text = _outputs(kb, tmp_path)
    assert "1970" not in text and not ISO.search(text)
    describe = runner.invoke(app, ["describe", "--kb", str(kb)]).output
    assert re.search(r"Time span 0\.000 s \.\. 14\.750 s of log time \(15 s\); now 14\.750 s\.", describe)


def test_a_wall_clock_log_prints_no_date_before_its_first_stamp(kbs, tmp_path):
    kb, first_s = kbs["wall"]
    text = _outputs(kb, tmp_path)
    dates = [datetime.fromisoformat(m.group(1)).replace(tzinfo=UTC) for m in ISO.finditer(text)]
    assert dates, "a wall-clock log's outputs carry its dates"
    first = datetime.fromtimestamp(first_s, UTC)
    assert min(dates) >= first, f"{min(dates)} is before the log's first stamp {first}"
    describe = runner.invoke(app, ["describe", "--kb", str(kb)]).output
    assert "Time span 2023-11-14T22:13:20.000Z .. 2023-11-14T22:13:34.750Z (15 s)" in describe
    answer = json.loads(runner.invoke(app, ["query", "chairs", "--json", "--kb", str(kb)]).stdout)
    assert answer["now"]["iso"] == "2023-11-14T22:13:34.750Z"
