"""Measure the README's figures and rewrite its table between the figures markers.

Usage: python scripts/readme_figures.py OUT [--only SECTIONS] [--logs LOG ...] [--render-only]

Sections: background, foreground, kb, worlds, qa, bench (default: all but bench, which takes
13-30 min). Each measures with hiper's own commands (`hiper eval background|foreground|qa`,
`hiper kb bench`, `hiper bench`, `hiper perceive` + the worlds' reference scorer) and stores its
rows, with where and when they were measured, in docs/readme_figures.json; sections not measured
in a run keep the rows they had. The README's block between `<!-- figures:begin -->` and
`<!-- figures:end -->` is then rendered from that file, so no figure there is typed by hand.

`--logs` measures on existing `hiper sim` logs instead of simulating fresh ones (SIM below);
`--render-only` rewrites the block from the JSON without measuring. Timings on a shared machine
are noisy: the provenance line of each section gives the load average it ran under.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
SHARED = next((p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared") if p.is_dir()),
              ROOT.parent / "shared")
WORLDS = Path(os.environ.get("HIPER_WORLDS", SHARED / "worlds"))
FIGURES = ROOT / "docs" / "readme_figures.json"
README = ROOT / "README.md"
BEGIN, END = "<!-- figures:begin -->", "<!-- figures:end -->"
ORDER = ("background", "foreground", "bench", "kb", "worlds", "qa")
# fresh `hiper sim` logs (world:seed) for background, foreground and QA; 60 s each
SIM = ("house:931", "house:932", "office:933", "hospital:934")
HEADER = ["| what | command | hiper | paper |", "|---|---|---|---|"]
Row = list[str]


# --- the block: rendering and replacing (what tests/test_readme_figures.py checks) ---

def render(figures: dict[str, Any]) -> str:
    """The Markdown between the markers: one table, then where each section's rows come from."""
    rows, sources = [], []
    for name in [*ORDER, *sorted(set(figures) - set(ORDER))]:
        section = figures.get(name)
        if not section:
            continue
        rows += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |"
                 for row in section["rows"]]
        sources.append(f"- {name}: {section['source']}")
    return "\n".join([*HEADER, *rows, "",
                      "Written by `python scripts/readme_figures.py OUT` from docs/readme_figures.json;",
                      "each section's rows come from:", "", *sources])


def replace_block(text: str, block: str) -> str:
    """`text` with what lies between the one BEGIN and the one END marker replaced by `block`."""
    if text.count(BEGIN) != 1 or text.count(END) != 1 or text.index(BEGIN) > text.index(END):
        raise ValueError(f"expected one {BEGIN} followed by one {END} in the README")
    head, rest = text.split(BEGIN)
    tail = rest.split(END)[1]
    return f"{head}{BEGIN}\n{block}\n{END}{tail}"


# --- running hiper ---

REUSE = False  # --reuse: read a command's saved output in OUT instead of running it again


def hiper(*args: str, out: Path | None = None) -> str:
    """Run `python -m hiper_cli ARGS` on this checkout; stdout (also written to `out`)."""
    if REUSE and out is not None and out.is_file():
        return out.read_text()
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.setdefault("HIPER_MODELS", str(SHARED / "models"))
    done = subprocess.run([sys.executable, "-m", "hiper_cli", *args], capture_output=True, text=True,
                          env=env, check=False)
    if out is not None:
        out.write_text(done.stdout)
        if done.stderr:
            out.with_name(out.name + ".err").write_text(done.stderr)
    if done.returncode:
        tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["(no output)"]
        sys.exit(f"readme_figures: hiper {' '.join(args)} failed: {tail[0]}")
    return done.stdout


def provenance(what: str) -> str:
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, check=False).stdout.strip() or "?"
    dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "hiper_cli"],
                           capture_output=True, text=True, check=False).stdout.strip()
    return (f"{dt.date.today().isoformat()} at {commit}{' + local changes' if dirty else ''}, "
            f"load average {os.getloadavg()[0]:.1f}; {what}")


def spread(values: list[float], fmt: str, unit: str = "") -> str:
    """`0.016-0.018 s` for a range, `0.016 s` for one value."""
    lo, hi = format(min(values), fmt), format(max(values), fmt)
    return (lo if lo == hi else f"{lo}-{hi}") + unit


def each(values: Sequence[float | None], fmt: str) -> str:
    """One value per log, in the logs' order; `-` where a log has none."""
    return ", ".join("-" if v is None else format(v, fmt) for v in values)


def sim_logs(out: Path, args: argparse.Namespace) -> list[Path]:
    if args.logs:
        return [Path(p) for p in args.logs]
    logs = []
    for spec in SIM:
        world, seed = spec.split(":")
        log = out / "logs" / f"{world}_{seed}"
        if not (log / "gt").is_dir():
            hiper("sim", "--world", world, "--seconds", str(args.sim_seconds), "--seed", seed, "-o", str(log),
                  "--overwrite")
        logs.append(log)
    return logs


def names(logs: list[Path]) -> str:
    return ", ".join(p.name for p in logs)


# --- the sections ---

def background(out: Path, args: argparse.Namespace) -> dict[str, Any]:
    logs = sim_logs(out, args)
    runs = [json.loads(hiper("eval", "background", str(log), "--json", out=out / f"bg_{log.name}.json"))
            for log in logs]
    cmd = "`hiper eval background LOG`"
    return {"rows": [
        ["background, per keyframe (one thread)", cmd, spread([r["time_mean_s"] for r in runs], ".3f", " s"),
         "0.157-0.202 s (i9)"],
        ["background static/dynamic; semantic precision", "same",
         f"{spread([100 * r['static_precision'] for r in runs], '.0f', ' %')}; "
         f"{spread([100 * r['semantic_precision'] for r in runs], '.0f', ' %')}", "98.4-100 %; 68.6-74.1 %"],
        ["background distance error", "same", spread([r["distance_mean_m"] for r in runs], ".3f", " m"),
         "0.022-0.033 m"],
    ], "source": provenance(f"logs {names(logs)}")}


def foreground(out: Path, args: argparse.Namespace) -> dict[str, Any]:
    logs = sim_logs(out, args)
    runs: dict[str, list[dict[str, Any]]] = {}
    for detector in args.detectors:
        runs[detector] = [json.loads(hiper("eval", "foreground", str(log), "--detector", detector,
                                           "--no-ablation", "--json",
                                           out=out / f"fg_{detector}_{log.name}.json"))["ours"]
                          for log in logs]
    first = args.detectors[0]
    per_log = f"{names(logs)}"
    fps = " / ".join(each([r["frames_per_s"] for r in runs[d]], ".1f") + f" (`{d}`)" for d in args.detectors)
    speed = " / ".join(each([r.get("moving_people_speed_error_mps") for r in runs[d]], "+.3f") + f" (`{d}`)"
                       for d in args.detectors)
    cmd = "`hiper eval foreground LOG --detector D --no-ablation`"
    return {"rows": [
        [f"foreground end to end, frames/s ({per_log})", cmd, fps, "~10 frames/s (GPU)"],
        [f"foreground false positives, `{first}` detector", "same",
         each([100 * r["fp_share"] for r in runs[first]], ".1f") + " %", "2.6-6.7 %"],
        [f"foreground localisation (classified observations, mean), `{first}`", "same",
         each([r["localisation_classified_m"][0] for r in runs[first]], ".4f") + " m", "0.014-0.020 m"],
        ["moving people's speed error vs truth", "same", speed + " m/s", "97.5 % below 0.58 (true 0.6) m/s"],
    ], "source": provenance(f"logs {per_log}; detectors {', '.join(args.detectors)}")}


def kb(out: Path, args: argparse.Namespace) -> dict[str, Any]:
    size = str(args.kb_size)
    run = json.loads(hiper("kb", "bench", "--sizes", size, "--json", out=out / "kb_bench.json"))[-1]
    p95 = max(v["p95_ms"] for v in run["latency"].values())
    return {"rows": [[
        f"knowledge base at {run['observations'] // 1000} k observations", f"`hiper kb bench --sizes {size}`",
        f"{run['end_to_end_obs_per_s'] / 1000:.1f} k obs/s end to end; p95 queries <= {p95:.0f} ms; "
        f"writer peak {run['peak_rss_mb']:.0f} MB; {run['size_on_disk_mb']:.0f} MB on disk", ""]],
        "source": provenance(f"{run['observations']} observations")}


def worlds(out: Path, args: argparse.Namespace) -> dict[str, Any]:
    scorer = WORLDS.parent / "tools" / "eval_scene.py"
    found = [WORLDS / w for w in args.worlds if (WORLDS / w / "gt").is_dir()]
    if not found:
        sys.exit(f"readme_figures: no world of {args.worlds} under {WORLDS} (set HIPER_WORLDS)")
    scores, fps = [], []
    for world in found:
        name = world.name
        kb_dir, export, metrics = out / f"{name}.hiper", out / f"{name}.json", out / f"{name}_m.json"
        start = time.monotonic()
        hiper("perceive", str(world), "--kb", str(kb_dir), "--replace", out=out / f"{world.name}.log")
        frames = sum(1 for line in (world / "rgb.txt").read_text().splitlines() if line and line[0] != "#")
        fps.append(frames / (time.monotonic() - start))
        hiper("export", str(export), "--kb", str(kb_dir), "--observations")
        subprocess.run([sys.executable, str(scorer), str(world / "gt"), str(export), "--json", str(metrics)],
                       capture_output=True, text=True, check=True)
        scores.append(json.loads(metrics.read_text()))
    fg = [s["foreground"] for s in scores]
    speed = [s["person_speed"]["mean_abs_error"] for s in scores
             if s.get("person_speed", {}).get("mean_abs_error") is not None]
    precision = ", ".join(f"{f['precision_classified']:.2f} ({f['tp']}; {f['fp_classified']})" for f in fg)
    cmd = "`hiper perceive WORLD` (`yolox`), `hiper export --observations`, the worlds' scorer"
    return {"rows": [
        [f"realistic worlds ({', '.join(w.name for w in found)}), `yolox`: classified precision (TP; FP); "
         "recall of nameable objects; walker speed error; background semantic precision", cmd,
         f"{precision}; {each([f['recall_nameable'] for f in fg], '.2f')}; {each(speed, '.3f')} m/s; "
         f"{each([s['background']['semantic_precision'] for s in scores], '.2f')}",
         "93-97 %; -; biased low; -"],
        ["realistic worlds, end to end with `yolox` (640x480)", "same (wall clock of `hiper perceive`)",
         each(fps, ".1f") + " frames/s", "~10 frames/s (GPU)"],
    ], "source": provenance(f"worlds under {WORLDS}")}


def qa(out: Path, args: argparse.Namespace) -> dict[str, Any]:
    logs = sim_logs(out, args)
    run = json.loads(hiper("eval", "qa", *map(str, logs), "-o", str(out / "qa"), "--detector", "truth",
                           "--json", out=out / "qa.json"))
    return {"rows": [[
        f"question answering on `hiper sim` logs (`truth` detector, {len(logs)} logs)",
        "`hiper eval qa LOG... --detector truth`",
        f"over all {run['questions']} questions: binary {run['binary_accuracy']:.3f}, count "
        f"{run['count_accuracy']:.3f}, median position error {run['position_error_median_m']:.3f} m, "
        f"median time error {run['time_error_median_s']:.3f} s",
        "DAAAM (OC-NaVQA, real data, cloud LLM): 0.711, 41.75 m, 1.79 min"]],
        "source": provenance(f"logs {names(logs)}")}


def bench(out: Path, args: argparse.Namespace) -> dict[str, Any]:
    start = time.monotonic()
    quick = ["--quick"] if args.quick_bench else []
    run = json.loads(hiper("bench", "-o", str(out / "bench"), "--json", *quick, out=out / "bench.json"))
    minutes = (time.monotonic() - start) / 60
    c1 = []
    for world, configs in run["tasks"].items():
        cells = configs.get("C1", {})
        c1.append(f"{world} " + ", ".join(f"{t} {c['successes']}/{c['runs']}" for t, c in cells.items()))
    settings = run["settings"]
    return {"rows": [[
        "the paper's ablation, C1 (the whole model): task successes per world",
        f"`hiper bench -o OUT{' --quick' if args.quick_bench else ''}` ({minutes:.0f} min)", "; ".join(c1),
        "-"]], "source": provenance(f"settings {json.dumps(settings, sort_keys=True)[:160]}")}


SECTIONS: dict[str, Callable[[Path, argparse.Namespace], dict[str, Any]]] = {
    "background": background, "foreground": foreground, "kb": kb, "worlds": worlds, "qa": qa, "bench": bench}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("out", type=Path, nargs="?", default=Path("out/readme_figures"))
    parser.add_argument("--only", default="background,foreground,kb,worlds,qa",
                        help="comma-separated sections to measure: " + ", ".join(SECTIONS))
    parser.add_argument("--logs", nargs="+", help="existing hiper sim logs instead of fresh ones")
    parser.add_argument("--sim-seconds", type=int, default=60)
    parser.add_argument("--detectors", type=lambda s: s.split(","), default=["truth", "yolox"])
    parser.add_argument("--worlds", type=lambda s: s.split(","), default=["bookstore", "warehouse"])
    parser.add_argument("--kb-size", type=int, default=500_000)
    parser.add_argument("--quick-bench", action="store_true", help="hiper bench --quick (a smoke run)")
    parser.add_argument("--render-only", action="store_true", help="rewrite the README from the JSON only")
    parser.add_argument("--reuse", action="store_true",
                        help="use the outputs a run left in OUT (same logs); the section keeps its source")
    args = parser.parse_args(argv)
    global REUSE
    REUSE = args.reuse
    figures: dict[str, Any] = json.loads(FIGURES.read_text()) if FIGURES.exists() else {}
    if not args.render_only:
        unknown = set(args.only.split(",")) - set(SECTIONS)
        if unknown:
            parser.error(f"--only {args.only!r}: unknown {sorted(unknown)}; expected some of "
                         f"{', '.join(SECTIONS)}")
        args.out.mkdir(parents=True, exist_ok=True)
        for name in args.only.split(","):
            print(f"readme_figures: measuring {name}", file=sys.stderr)
            old = figures.get(name, {}).get("source")
            figures[name] = SECTIONS[name](args.out, args)
            if args.reuse and old:
                figures[name]["source"] = f"{old}; rendered again from its outputs"
            FIGURES.write_text(json.dumps(figures, indent=1, ensure_ascii=False) + "\n")
    README.write_text(replace_block(README.read_text(), render(figures)))
    print(f"readme_figures: README.md rewritten from {FIGURES.relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
