"""The paper's benchmark (section VII) offline: the ablation C1-C5 over tasks T1-T4 (``hiper bench``).

    from hiper_cli.bench import BenchSettings, run_bench, summarize, write_report
    result = run_bench(BenchSettings(worlds=("house",), runs=2, log_s=90), Path("out/bench"))
    write_report(result, summarize(result), Path("out/bench"), "hiper bench ...")

Configurations (``configs``), the C5 box projection (``baseline``), perception and Tables II/III
per configuration (``perception``), the map and camera (``nav``), the robot among the sim's people
(``robot``), search strategies (``search``), the tasks (``tasks``), the run (``run``), its numbers
(``summary``) and the Markdown report (``report``).
"""

from hiper_cli.bench.configs import CONFIGS, BenchConfig, parse_configs
from hiper_cli.bench.report import require_matplotlib, write_report
from hiper_cli.bench.run import WORLD_NAMES, BenchResult, BenchSettings, run_bench
from hiper_cli.bench.summary import summarize
from hiper_cli.bench.tasks import TASKS, TaskConfig, TaskResult

__all__ = [
    "CONFIGS",
    "TASKS",
    "WORLD_NAMES",
    "BenchConfig",
    "BenchResult",
    "BenchSettings",
    "TaskConfig",
    "TaskResult",
    "parse_configs",
    "require_matplotlib",
    "run_bench",
    "summarize",
    "write_report",
]
