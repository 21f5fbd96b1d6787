"""One fault case, and the workspace helpers several categories share.

A ``Case`` is one ``hiper`` command line (``{kb}``, ``{log}``, ``{root}``, ``{export}``,
``{mcap}``, ``{bag}`` are filled from the case's workspace), what to do to the workspace first,
what it must end in (``expect``: ok, error or usage) and what the knowledge base must look like
after it (``kb``: intact = same documents and ``kb check --no-repair`` passes; consistent =
check passes; unchanged = not one file touched; absent = never created; repairable = ``kb
check`` rebuilds what the case damaged, then intact; None = no knowledge base involved).
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from tests.faults.runner import Result, Workspace


@dataclass(frozen=True)
class Case:
    name: str
    group: str
    argv: tuple[str, ...]
    expect: str  # ok | error | usage | any (ok or a clean error)
    behaviour: str
    prepare: Callable[[Workspace], None] | None = None
    kb: str | None = "intact"
    check: Callable[[Workspace, Result], str | None] | None = None
    fsize_limit: int | None = None
    timeout_s: float = 90.0
    # instead of running ``argv``: drive hiper from the user's side some other way (a server
    # and its HTTP clients, two processes at once) and report it as one Result
    probe: Callable[[Workspace], Result] | None = None


def argv(text: str) -> tuple[str, ...]:
    return tuple(text.split())


def small_disk(ws: Workspace) -> None:
    """A 900 KB file system at ``{root}/small`` (root only; elsewhere the case is limited by
    RLIMIT_FSIZE instead)."""
    small = ws.root / "small"
    small.mkdir()
    if os.geteuid() == 0 and mount("-t", "tmpfs", "-o", "size=900k", "tmpfs", str(small)):
        ws.cleanups.append(lambda: umount(small))


def mount(*args: str) -> bool:
    return subprocess.run(["mount", *args], capture_output=True).returncode == 0


def umount(path: Path) -> None:
    subprocess.run(["umount", "-l", str(path)], capture_output=True)
