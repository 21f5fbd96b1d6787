"""Option values out of range: one line naming the option and its range, exit 2."""

from __future__ import annotations

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.case import argv as _argv
from tests.faults.runner import Result, Workspace


def cases() -> list[Case]:
    sim = "sim --out {root}/sim --seconds 2 --width 64 --height 48"
    rows = [
        ("sim-seconds-inf", sim.replace("--seconds 2", "--seconds inf")),
        ("sim-seconds-negative", sim.replace("--seconds 2", "--seconds -5")),
        ("sim-rate-nan", sim + " --rate-hz nan"),
        ("sim-seed-negative", sim + " --seed -1"),
        ("sim-width-huge", sim.replace("--width 64", "--width 1000000")),
        ("sim-false-positives-huge", sim + " --false-positives 1e9"),
        ("sim-miss-rate-above-one", sim + " --miss-rate 2"),
        ("sim-png-compression", sim + " --png-compression 12"),
        ("eval-max-frames-negative", "eval foreground {log} --max-frames -1"),
        ("bench-obs-per-frame-zero", "kb bench --sizes 100 --obs-per-frame 0"),
        ("bench-queries-negative", "kb bench --sizes 100 --queries -3"),
        ("bench-sync-nan", "kb bench --sizes 100 --graph-sync-s nan"),
        ("reanchor-max-dt-inf", "reanchor --kb {kb} --poses {log}/groundtruth.txt --max-dt-s inf"),
    ]
    perceive = ("perceive", "{log}", "--kb", "{root}/new.hiper", "--detector", "truth")
    refused = [  # the second probe: accepted with exit 0 before
        ("classes-only-commas", (*perceive, "--classes", ",,,")),
        ("exclude-unknown-class", (*perceive, "--exclude-classes", "unicorn")),
        ("class-kept-and-excluded", (*perceive, "--classes", "cup", "--exclude-classes", "cup")),
        ("env-empty", (*perceive, "--env", "")),
        ("env-blank", (*perceive, "--env", "   ")),
        ("kb-docs-without-endpoint", (*perceive, "--kb-docs", "{root}/docs.hiper")),
        ("query-at-nan", ("query", "cups", "--at", "nan", "--kb", "{kb}")),
        ("query-now-nan", ("query", "cups", "--now", "nan", "--kb", "{kb}")),
        ("query-now-inf", ("query", "cups", "--now", "inf", "--kb", "{kb}")),
        ("query-pose-huge", ("query", "cups", "--pose", "1e308,1e308,0,0", "--kb", "{kb}")),
        ("query-pose-nan", ("query", "cups", "--pose", "nan,0,0,0", "--kb", "{kb}")),
        ("query-sparql-and-words", ("query", "cups", "--sparql", "ASK {{}}", "--kb", "{kb}")),
        ("convert-onto-itself", ("convert", "{root}/log", "{root}/log", "--to", "tum", "--overwrite")),
        ("convert-into-itself", ("convert", "{root}/log", "{root}/log/inner", "--to", "tum")),
        ("analyze-empty-folder", ("analyze", "features", "--kb", "{root}/empty")),
        ("analyze-heatmap-empty-folder", ("analyze", "heatmap", "--kb", "{root}/empty")),
    ]
    cases = [Case(f"options/{n}", "options", _argv(a), "usage", "one line naming the option and its range",
                  kb=None, timeout_s=30.0) for n, a in rows]
    cases += [Case(f"options/{n}", "options", a, "error", "one line naming the value and the fix; nothing "
                   "written", kb="intact" if "{kb}" in a else None, prepare=_prepare, check=_nothing_made,
                   timeout_s=60.0) for n, a in refused]
    return cases


def _prepare(ws: Workspace) -> None:
    (ws.root / "empty").mkdir()
    inputs.copy_log(ws.root / "log")


def _nothing_made(ws: Workspace, result: Result) -> str | None:
    made = [p.name for p in ws.root.iterdir() if p.name in ("new.hiper", "docs.hiper")]
    made += [f"empty/{p.name}" for p in (ws.root / "empty").iterdir()]
    made += ["log/inner"] if (ws.root / "log" / "inner").exists() else []
    return f"a refused command wrote {made}" if made else None
