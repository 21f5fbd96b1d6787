"""``hiper bench`` as a function: settings from its flags, the run, the summary and the report."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["QUICK_LOG_S", "QUICK_MAPPING_S", "QUICK_RUNS", "QUICK_WORLDS", "benchmark"]

# --quick: one world, 2 runs, a short log (CI: a few minutes)
QUICK_WORLDS, QUICK_RUNS, QUICK_LOG_S, QUICK_MAPPING_S = "house", 2, 90.0, 30.0


def benchmark(out: Path, command: str, *, quick: bool = False, worlds: str | None = None,
              configs: str | None = None, runs: int | None = None, seed: int = 0, log_s: float | None = None,
              mapping_s: float | None = None, time_limit_s: float = 600.0,
              on_start: Callable[[int], None] | None = None,
              progress: Callable[[str, int], None] | None = None) -> dict[str, Any]:
    """Run the benchmark into ``out`` (``run_bench``), write ``out/report.md`` (``command`` is
    quoted in it) and return the summary with the report's path. Unset choices take the
    paper's values (all worlds, 10 runs, 600 s logs, 60 s mapping), or the ``QUICK_*`` ones with
    ``quick``. ``on_start(units)`` once the settings are checked; ``progress(what, n)`` per unit."""
    from hiper_cli.bench.configs import parse_configs
    from hiper_cli.bench.report import require_matplotlib, write_report
    from hiper_cli.bench.run import BenchSettings, run_bench
    from hiper_cli.bench.summary import summarize
    from hiper_cli.bench.tasks import TaskConfig

    require_matplotlib()
    world_text = worlds or (QUICK_WORLDS if quick else "house,hospital,office")
    settings = BenchSettings(
        worlds=tuple(w.strip() for w in world_text.split(",") if w.strip()),
        configs=parse_configs(configs), runs=runs or (QUICK_RUNS if quick else 10), seed=seed,
        log_s=log_s or (QUICK_LOG_S if quick else 600.0),
        mapping_s=mapping_s or (QUICK_MAPPING_S if quick else 60.0),
        tasks=TaskConfig(time_limit_s=time_limit_s),
    )
    if on_start is not None:
        on_start(settings.units())
    result = run_bench(settings, out, progress)
    summary = summarize(result)
    summary["report"] = str(write_report(result, summary, out, command))
    return summary
