"""Usage errors through the installed ``hiper`` script: the usage line, one red line naming the
bad word with the nearest valid command or option, exit code 2, never a traceback."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(sys.executable).with_name("hiper")


def hiper(*args: str) -> subprocess.CompletedProcess[str]:
    script = str(SCRIPT) if SCRIPT.is_file() else shutil.which("hiper")
    assert script, "the hiper entry point is not installed (pip install -e .)"
    return subprocess.run([script, *args], capture_output=True, text=True, timeout=60,
                          env={**os.environ, "COLUMNS": "200", "NO_COLOR": "1"})


@pytest.mark.parametrize(
    ("args", "usage", "message"),
    [
        (["zzz"], "Usage: hiper [OPTIONS] COMMAND",
         "no such command 'zzz' for 'hiper'; expected one of"),
        (["perceve"], "Usage: hiper [OPTIONS] COMMAND", "did you mean 'perceive'?"),
        (["kb", "chek"], "Usage: hiper kb [OPTIONS] COMMAND",
         "no such command 'chek' for 'hiper kb'; did you "
                                                            "mean 'check'?"),
        (["perceive", "--stage", "x", "log"], "Usage: hiper perceive", "no such option '--stage' for 'hiper "
                                                                       "perceive'; did you mean '--stages'?"),
        (["info"], "Usage: hiper info", "Missing argument"),
        (["sim", "--seed", "abc", "--out", "x"], "Usage: hiper sim", "Invalid value for '--seed'"),
    ],
    ids=["unknown-command", "command-typo", "subcommand-typo", "option-typo", "missing-argument",
         "bad-value"],
)
def test_usage_error(args: list[str], usage: str, message: str) -> None:
    result = hiper(*args)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 2, result.stderr  # the usage line and one error line
    assert lines[0].startswith(usage), result.stderr
    assert lines[1].startswith("error: ") and message in lines[1], result.stderr
    assert result.stdout == ""


def test_out_of_range_option_is_a_usage_error() -> None:
    result = hiper("sim", "--seconds", "inf", "--out", "unused")
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip() == "error: --seconds inf: expected a finite number in (0, 86400]"


def test_a_group_without_command_prints_its_help() -> None:
    result = hiper("kb")
    assert result.returncode == 2
    assert "check" in result.stdout + result.stderr and "Traceback" not in result.stderr
