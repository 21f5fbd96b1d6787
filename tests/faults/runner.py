"""Run fault cases: each one ``hiper`` process under a time limit, then judge what it did.

A case passes when the process ended in time, printed no traceback, exited as the case expects
(0, or a non-zero code with exactly one ``error:`` line on stderr, plus the usage line for a
usage error), and left the knowledge base as the case demands (``kb check --no-repair`` passes
and no document is lost). ``hiper`` runs as ``python -c BOOT`` importing ``hiper_cli`` from
``repo`` so the same corpus measures another checkout.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
TRACEBACK = "Traceback (most recent call last)"
# import hiper_cli from REPO even where another checkout is installed in editable mode
BOOT = (
    "import sys; repo = sys.argv.pop(1); "
    "sys.meta_path[:] = [f for f in sys.meta_path if 'editable' not in repr(f).lower()]; "
    "sys.path.insert(0, repo); sys.argv[0] = 'hiper'; from hiper_cli.cli import main; main()"
)


def hiper_argv(repo: Path, args: Sequence[str]) -> list[str]:
    return [sys.executable, "-c", BOOT, str(repo), *args]


@dataclass
class Result:
    returncode: int
    stdout: str
    stderr: str
    seconds: float
    timed_out: bool = False


@dataclass
class Workspace:
    """One case's private folder: a copy of the template knowledge base and what it needs."""

    root: Path
    cache: Path
    repo: Path
    cleanups: list[Callable[[], None]] = field(default_factory=list)
    extra: dict[str, str] = field(default_factory=dict)  # more {name} values a preparation sets

    @property
    def kb(self) -> Path:
        return self.root / "scene.hiper"

    def values(self) -> dict[str, str]:
        return {"root": str(self.root), "kb": str(self.kb), "log": str(self.cache / "log"),
                "export": str(self.cache / "export.json"), "mcap": str(self.cache / "log.mcap"),
                "bag": str(self.cache / "log.bag"), **self.extra}

    def hiper(self, *args: str, timeout_s: float = 120.0, fsize: int | None = None) -> Result:
        return run_hiper(self.repo, [a.format(**self.values()) for a in args], self.root, timeout_s, fsize)


def _limit_file_size(limit: int) -> Callable[[], None]:
    def apply() -> None:
        import resource

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


def run_hiper(repo: Path, args: Sequence[str], cwd: Path, timeout_s: float, fsize: int | None = None,
              env: dict[str, str] | None = None) -> Result:
    start = time.monotonic()
    proc = subprocess.Popen(hiper_argv(repo, args), cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, errors="replace", start_new_session=True,
                            env={**os.environ, "COLUMNS": "200", "NO_COLOR": "1", **(env or {})},
                            preexec_fn=_limit_file_size(fsize) if fsize else None)
    try:
        out, err = proc.communicate(timeout=timeout_s)
        return Result(proc.returncode, out, err, time.monotonic() - start)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        return Result(-9, out, err, time.monotonic() - start, timed_out=True)


def build_cache(repo: Path, cache: Path) -> dict[str, Any]:
    """The shared inputs: the fixture log, a knowledge base perceived from it, its JSON export,
    the log as MCAP and rosbag1. Returns the template's totals."""
    from tests.faults.inputs import FIXTURE

    totals_file = cache / "totals.json"
    if totals_file.is_file():
        return dict(json.loads(totals_file.read_text()))
    cache.mkdir(parents=True, exist_ok=True)
    shutil.copytree(FIXTURE, cache / "log", dirs_exist_ok=True)
    steps = [
        # every observation kept: the export must outgrow the small disk of the disk-full cases
        ["perceive", str(cache / "log"), "--kb", str(cache / "template.hiper"), "--detector", "truth",
         "--keep-observations", "all", "--json"],
        ["export", str(cache / "export.json"), "--kb", str(cache / "template.hiper"), "--format", "json"],
        ["convert", str(cache / "log"), str(cache / "log.mcap"), "--to", "mcap", "--json"],
        ["convert", str(cache / "log"), str(cache / "log.bag"), "--to", "rosbag1", "--json"],
    ]
    for args in steps:
        result = run_hiper(repo, args, cache, 300.0)
        if result.returncode != 0:
            raise RuntimeError(f"fault-suite set-up failed: hiper {' '.join(args)}: {result.stderr[-2000:]}")
    totals = kb_state(repo, cache / "template.hiper", cache)
    if totals is None:
        raise RuntimeError("fault-suite set-up: the template knowledge base does not read back")
    totals_file.write_text(json.dumps(totals))
    return totals


def kb_state(repo: Path, kb: Path, cwd: Path) -> dict[str, Any] | None:
    """Document totals and sessions of a knowledge base as ``hiper kb info --json`` reports
    them, None when it cannot be read."""
    result = run_hiper(repo, ["kb", "info", "--kb", str(kb), "--json"], cwd, 60.0)
    if result.returncode != 0:
        return None
    data = json.loads(result.stdout)
    return {"totals": data["totals"], "frames": sum(s["frames"] for s in data["sessions"]),
            "sessions": len(data["sessions"])}


def kb_problems(repo: Path, kb: Path, cwd: Path, expected: dict[str, Any] | None) -> list[str]:
    """What is wrong with a knowledge base after a case: it does not read, ``kb check
    --no-repair`` fails, or (``expected``) it holds other documents than the template."""
    state = kb_state(repo, kb, cwd)
    if state is None:
        why = _last_line(run_hiper(repo, ["kb", "info", "--kb", str(kb)], cwd, 60.0))
        return [f"the knowledge base does not open any more ({why})"]
    check = run_hiper(repo, ["kb", "check", "--no-repair", "--kb", str(kb)], cwd, 60.0)
    problems = [] if check.returncode == 0 else [f"kb check --no-repair: {_last_line(check)}"]
    if expected is not None and state != expected:
        problems.append(f"documents changed: {state} (was {expected})")
    return problems


def _last_line(result: Result) -> str:
    lines = [ln for ln in (result.stderr + result.stdout).splitlines() if ln.strip()]
    return lines[-1][:300] if lines else ""


def error_lines(stderr: str) -> tuple[list[str], list[str]]:
    """The ``error:`` lines of stderr, and every other non-empty line except the usage line."""
    errors, other = [], []
    for line in stderr.splitlines():
        if not line.strip() or line.startswith("Usage:"):
            continue
        (errors if line.startswith("error:") else other).append(line)
    return errors, other


@dataclass
class Outcome:
    name: str
    group: str
    behaviour: str
    verdict: str  # pass | traceback | hang | data loss | misleading success | unclean | failed
    exit_code: int
    message: str
    seconds: float
    problems: list[str] = field(default_factory=list)

    @property
    def clean_error(self) -> bool:
        return self.verdict == "pass" and self.exit_code != 0


def judge(case: Any, result: Result, problems: list[str]) -> Outcome:
    errors, other = error_lines(result.stderr)
    message = errors[0][len("error:"):].strip() if errors else _last_line(result)
    if result.timed_out:
        verdict = "hang"
    elif TRACEBACK in result.stderr or TRACEBACK in result.stdout:
        verdict, message = "traceback", _last_line(result)
    elif problems and any(p.startswith(("the knowledge base", "documents changed", "kb check", "lost"))
                          for p in problems):
        verdict = "data loss"
    elif case.expect in ("error", "usage") and result.returncode == 0:
        verdict, message = "misleading success", "exit 0"
    elif case.expect == "ok" and result.returncode != 0:
        verdict = "failed"
    elif result.returncode != 0 and (len(errors) != 1 or other):
        verdict = "unclean"
    elif case.expect == "usage" and result.returncode != 2:
        verdict = "failed"
        problems = [*problems, f"exit code {result.returncode}, expected 2"]
    elif problems:
        verdict = "failed"
    else:
        verdict = "pass"
    if case.expect == "ok" and result.returncode == 0 and verdict == "pass":
        message = "ok"
    return Outcome(case.name, case.group, case.behaviour, verdict, result.returncode, message,
                   round(result.seconds, 2), problems)


def run_case(case: Any, repo: Path, cache: Path, totals: dict[str, Any]) -> Outcome:
    with tempfile.TemporaryDirectory(prefix="hiper-fault-") as tmp:
        ws = Workspace(Path(tmp), cache, repo)
        try:
            if case.kb is not None and case.kb != "absent":
                shutil.copytree(cache / "template.hiper", ws.kb)
            if case.prepare is not None:
                try:
                    case.prepare(ws)
                except Exception as err:  # the case could not be set up: report, do not stop the suite
                    return Outcome(case.name, case.group, case.behaviour, "failed", -1,
                                   f"set-up failed: {err!r}"[:300], 0.0, [f"set-up failed: {err!r}"])
            before = _kb_snapshot(ws.kb) if case.kb == "unchanged" else None
            if case.probe is not None:
                try:
                    result = case.probe(ws)
                except Exception as err:  # a probe that breaks: report it, do not stop the suite
                    return Outcome(case.name, case.group, case.behaviour, "failed", -1,
                                   f"probe failed: {err!r}"[:300], 0.0, [f"probe failed: {err!r}"])
            else:
                result = ws.hiper(*case.argv, timeout_s=case.timeout_s, fsize=case.fsize_limit)
            problems = _verify(case, ws, result, totals, before)
        finally:
            for cleanup in reversed(ws.cleanups):
                cleanup()
    return judge(case, result, problems)


def _kb_snapshot(kb: Path) -> dict[str, Any]:
    from tests.faults.inputs import snapshot

    # the documents and anything else, not the scene graph (derived; RocksDB rewrites files on open)
    return {k: v for k, v in snapshot(kb).items() if not k.startswith("graph/")} if kb.is_dir() else {}


def _verify(case: Any, ws: Workspace, result: Result, totals: dict[str, Any],
            before: dict[str, Any] | None) -> list[str]:
    problems: list[str] = []
    if result.timed_out:
        return problems
    mode = case.kb
    if mode == "unchanged" and _kb_snapshot(ws.kb) != before:  # before the check opens it
        problems.append("documents changed: files of the refused folder were modified")
    if case.check is not None:
        found = case.check(ws, result)
        if found:
            problems.append(found)
    if mode == "absent" and ws.kb.exists():
        problems.append(f"{ws.kb} was created")
    elif mode == "intact":
        problems += kb_problems(ws.repo, ws.kb, ws.root, totals)
    elif mode == "consistent":
        problems += kb_problems(ws.repo, ws.kb, ws.root, None)
    elif mode == "repairable":  # damage the case injected: kb check rebuilds, nothing lost
        repair = ws.hiper("kb", "check", "--kb", "{kb}", timeout_s=120.0)
        if repair.returncode != 0:
            problems.append(f"kb check (repair) failed: {_last_line(repair)}")
        problems += kb_problems(ws.repo, ws.kb, ws.root, totals)
    return problems


def _kill_command(kind: str, ws: Workspace) -> list[str]:
    """The command of a kill case, its inputs set up in ``ws``."""
    values = ws.values()
    if kind == "perceive":
        return ["perceive", values["log"], "--kb", values["kb"], "--detector", "truth", "--json"]
    if kind == "export":
        shutil.copytree(ws.cache / "template.hiper", ws.kb)
        shutil.copy(ws.cache / "export.json", ws.root / "out.json")
        return ["export", str(ws.root / "out.json"), "--kb", values["kb"], "--format", "json",
                "--observations"]
    if kind == "startup":  # what every command pays before it touches the knowledge base
        return ["kb", "info", "--help"]
    if kind == "check":  # a damaged scene graph, rebuilt from the documents by kb check
        from tests.faults.inputs import damage_graph

        shutil.copytree(ws.cache / "template.hiper", ws.kb)
        damage_graph(ws.kb, "sst")
        return ["kb", "check", "--kb", values["kb"]]
    if kind == "analyze":
        shutil.copytree(ws.cache / "template.hiper", ws.kb)
        return ["analyze", "features", "--kb", values["kb"], "--json"]
    if kind == "reanchor":
        shutil.copytree(ws.cache / "template.hiper", ws.kb)
        return ["reanchor", "--kb", values["kb"], "--poses", values["log"] + "/groundtruth.txt", "--json"]
    return ["import", values["export"], "--kb", values["kb"]]


KILL_ATTEMPTS = 3
_TIMING = threading.Lock()
KILLS_SPREAD = 10  # the moments of one kind are spread over this many slices of its run


def _duration(kind: str, repo: Path, cache: Path) -> float:
    """Seconds an uninterrupted run of the kill case's command takes here (measured once)."""
    timing = cache / f"duration-{kind}.txt"
    with _TIMING:  # measured once, by one thread: the others wait for it
        if not timing.is_file():
            with tempfile.TemporaryDirectory(prefix="hiper-time-") as tmp:
                ws = Workspace(Path(tmp), cache, repo)
                result = run_hiper(repo, _kill_command(kind, ws), ws.root, 300.0)
            timing.write_text(str(result.seconds))
        return float(timing.read_text())


def kill_case(kind: str, index: int, repo: Path, cache: Path, totals: dict[str, Any]) -> Outcome:
    """Start a perceive, export, import, analyze, reanchor or kb check (rebuilding a damaged
    graph; a second kb check must finish the repair), kill -9 it at the ``index``-th of
    ten moments of its run, and check that the knowledge base reopens consistent (``kb check``)
    with nothing committed lost, and that an export target holds either the earlier export or a
    complete new one.

    A run that finishes before its kill (the machine got faster than when the duration was
    measured) is checked too, then tried again with an instant drawn within its own duration."""
    rng = random.Random(f"{kind}-{index}")
    duration = _duration(kind, repo, cache)
    # ten moments spread over the run after Python has started and imported hiper (a kill
    # before that tests nothing), each jittered within its tenth
    startup = min(_duration("startup", repo, cache), 0.8 * duration)
    share = (index + rng.uniform(0.05, 0.95)) / max(1, KILLS_SPREAD)
    for _attempt in range(KILL_ATTEMPTS):
        delay = startup + min(share, 0.97) * (duration - startup)
        outcome = _kill_once(kind, index, delay, repo, cache, totals)
        if outcome.verdict != "pass" or outcome.exit_code == -signal.SIGKILL:
            return outcome
        duration = min(duration, outcome.seconds)
        share = rng.uniform(0.3, 0.95)
    return outcome


def _kill_once(kind: str, index: int, delay: float, repo: Path, cache: Path,
               totals: dict[str, Any]) -> Outcome:
    with tempfile.TemporaryDirectory(prefix="hiper-kill-") as tmp:
        ws = Workspace(Path(tmp), cache, repo)
        args = _kill_command(kind, ws)
        proc = subprocess.Popen(hiper_argv(repo, args), cwd=ws.root, stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True, start_new_session=True)
        start = time.monotonic()
        try:
            proc.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        seconds = time.monotonic() - start
        problems: list[str] = []
        if TRACEBACK in err:
            return Outcome(f"kill -9 {kind} #{index}", "kill", "", "traceback", proc.returncode,
                           err.strip().splitlines()[-1], round(seconds, 2))
        if kind == "export":
            problems += kb_problems(repo, ws.kb, ws.root, totals)
            try:
                data = json.loads((ws.root / "out.json").read_text())
                if data.get("format") != "hiper-kb-export":
                    problems.append("lost: the export file is not an export")
            except (OSError, ValueError) as err_json:
                problems.append(f"lost: the export file is damaged ({err_json})")
        elif ws.kb.exists() and (ws.kb / "documents.sqlite").exists():
            if kind == "check":  # killed while rebuilding a damaged graph: the next check finishes it
                repair = run_hiper(repo, ["kb", "check", "--kb", str(ws.kb)], ws.root, 120.0)
                if repair.returncode != 0:
                    problems.append(f"kb check after the kill failed: {_last_line(repair)}")
            problems += kb_problems(repo, ws.kb, ws.root, totals if kind == "check" else None)
            if kind == "import":
                state = kb_state(repo, ws.kb, ws.root)
                if state and state["totals"]["instance"] not in (0, totals["totals"]["instance"]):
                    problems.append(f"lost: a partial import ({state['totals']})")
    killed = proc.returncode == -signal.SIGKILL
    behaviour = f"killed after {delay:.2f} s" if killed else f"finished before the kill ({seconds:.1f} s)"
    verdict = "data loss" if problems else "pass"
    return Outcome(f"kill -9 {kind} #{index}", "kill", behaviour, verdict, proc.returncode,
                   "; ".join(problems) or "knowledge base consistent", round(seconds, 2), problems)


def summarise(outcomes: Sequence[Outcome]) -> dict[str, int]:
    verdicts = [o.verdict for o in outcomes]
    return {
        "cases": len(outcomes),
        "passed": verdicts.count("pass"),
        "clean_errors": sum(o.clean_error for o in outcomes if o.group != "kill"),
        "tracebacks": verdicts.count("traceback"),
        "hangs": verdicts.count("hang"),
        "data_loss": verdicts.count("data loss"),
        "misleading_successes": verdicts.count("misleading success"),
        "unclean_messages": verdicts.count("unclean"),
        "other_failures": verdicts.count("failed"),
    }
