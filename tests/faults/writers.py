"""Two hiper processes on one knowledge base at once: two ``perceive`` runs, two imports, an
import or an analysis during a run, a reader during a run. Each process ends in success or one
clear error line (it waits for the other writer or refuses), and afterwards the knowledge base
passes ``kb check`` with every successful run's frames in it.
"""

from __future__ import annotations

import shutil
import subprocess
import time
from collections.abc import Callable, Sequence

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.runner import TRACEBACK, Result, Workspace, error_lines, hiper_argv, kb_problems, kb_state

FRAMES = 60  # the fixture log's frames


def _together(commands: Sequence[Sequence[str]], after: Callable[[Workspace, list[Result]], list[str]],
              stagger_s: float = 0.3) -> Callable[[Workspace], Result]:
    """Start ``commands`` ``stagger_s`` apart, wait for all, then judge each and ``after``."""
    def probe(ws: Workspace) -> Result:
        inputs.copy_log(ws.root / "log2")
        start = time.monotonic()
        procs = []
        for k, command in enumerate(commands):
            if k:
                time.sleep(stagger_s)
            args = [a.format(**ws.values()) for a in command]
            procs.append(subprocess.Popen(hiper_argv(ws.repo, args), cwd=ws.root, stdout=subprocess.PIPE,
                                          stderr=subprocess.PIPE, text=True))
        results = []
        for proc in procs:
            try:
                out, err = proc.communicate(timeout=240)
            except subprocess.TimeoutExpired:
                proc.kill()
                out, err = proc.communicate()
                err += "\nerror: did not finish in 240 s (waits forever for the other writer?)"
            results.append(Result(proc.returncode, out, err, time.monotonic() - start))
        problems: list[str] = []
        for command, result in zip(commands, results, strict=True):
            errors, other = error_lines(result.stderr)
            if result.returncode != 0 and (len(errors) != 1 or other) and TRACEBACK not in result.stderr:
                problems.append(f"'{command[0]}' exit {result.returncode} without one clear error line: "
                                f"{result.stderr.strip()[-200:]!r}")
        if all(r.returncode != 0 for r in results):
            problems.append("no process succeeded")
        problems += after(ws, results)
        tracebacks = "".join(r.stderr for r in results if TRACEBACK in r.stderr)
        summary = "; ".join(f"{c[0]} exit {r.returncode}" for c, r in zip(commands, results, strict=True))
        return Result(1 if problems else 0, summary, tracebacks + (f"error: {'; '.join(problems)}\n"
                                                                   if problems else ""),
                      time.monotonic() - start)

    return probe


PERCEIVE = ("perceive", "{log}", "--kb", "{root}/w.hiper", "--detector", "truth", "--json")
PERCEIVE_2 = ("perceive", "{root}/log2", "--kb", "{root}/w.hiper", "--detector", "truth", "--json")
IMPORT = ("import", "{export}", "--kb", "{root}/w.hiper")


def _runs_kept(ws: Workspace, results: list[Result]) -> list[str]:
    """kb check passes and every perceive run that succeeded left a finished session of all
    its frames."""
    kb = ws.root / "w.hiper"
    problems = kb_problems(ws.repo, kb, ws.root, None)
    state = kb_state(ws.repo, kb, ws.root)
    if state is None:
        return problems
    succeeded = sum(r.returncode == 0 and '"frames_read"' in r.stdout for r in results)
    if state["frames"] != FRAMES * succeeded + int(ws.extra.get("frames_before", "0")):
        problems.append(f"lost: {state['frames']} frames stored for {succeeded} successful runs of {FRAMES}")
    return problems


def _import_complete(ws: Workspace, results: list[Result]) -> list[str]:
    """kb check passes and the imported documents are all there (the same as the template's)."""
    kb = ws.root / "w.hiper"
    problems = kb_problems(ws.repo, kb, ws.root, None)
    state = kb_state(ws.repo, kb, ws.root)
    template = kb_state(ws.repo, ws.cache / "template.hiper", ws.root)
    if state and template and state["totals"]["instance"] < template["totals"]["instance"]:
        problems.append(f"lost: {state['totals']} after the imports (template {template['totals']})")
    return problems


def _fresh_template(ws: Workspace) -> None:
    shutil.copytree(ws.cache / "template.hiper", ws.root / "w.hiper")
    ws.extra["frames_before"] = str(FRAMES)


def cases() -> list[Case]:
    def case(name: str, behaviour: str, commands: Sequence[Sequence[str]],
             after: Callable[[Workspace, list[Result]], list[str]], **extra: object) -> Case:
        return Case(f"writers/{name}", "writers", (), "ok", behaviour, probe=_together(commands, after),
                    kb=None, timeout_s=300.0, **extra)  # type: ignore[arg-type]

    return [
        case("two-perceive-two-logs", "the second waits or refuses clearly; both runs' frames kept",
             [PERCEIVE, PERCEIVE_2], _runs_kept),
        case("two-perceive-one-log", "the second waits and is refused as the same log, or refuses clearly",
             [PERCEIVE, PERCEIVE], _runs_kept),
        case("two-imports", "both imports succeed (the same documents) or the second refuses clearly",
             [IMPORT, IMPORT], _import_complete),
        case("import-during-perceive", "the import waits or refuses clearly; the run's frames kept",
             [PERCEIVE_2, IMPORT], _runs_kept),
        case("reader-during-perceive", "kb info reads (the graph may lag) or refuses clearly",
             [PERCEIVE, ("kb", "info", "--kb", "{root}/w.hiper", "--json")], _runs_kept),
        case("analyze-during-perceive", "analyze waits or refuses clearly; the run's frames kept",
             [PERCEIVE_2, ("analyze", "features", "--kb", "{root}/w.hiper", "--json")], _runs_kept,
             prepare=_fresh_template),
    ]
