"""``run_bench``: the whole benchmark, per world a log, its perception per configuration and the
task episodes (``tasks.run_episode``), with the seeds that reproduce it."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.bench.configs import CONFIGS, BenchConfig
from hiper_cli.bench.tasks import TaskConfig, TaskResult, run_episode
from hiper_cli.errors import ConfigError

__all__ = ["WORLD_NAMES", "BenchResult", "BenchSettings", "run_bench"]

WORLD_NAMES = ("house", "hospital", "office")
Progress = Callable[[str, int], None]  # (what runs now, units done since the last call)


@dataclass(frozen=True)
class BenchSettings:
    """What a benchmark run is: worlds, runs per task and configuration, log shape, seed."""

    worlds: tuple[str, ...] = WORLD_NAMES
    configs: tuple[BenchConfig, ...] = tuple(CONFIGS.values())
    runs: int = 10
    seed: int = 0
    log_s: float = 600.0  # the simulated log per world (mapping phase included)
    mapping_s: float = 60.0
    rate_hz: float = 5.0
    width_px: int = 320
    height_px: int = 240
    tasks: TaskConfig = field(default_factory=TaskConfig)

    def __post_init__(self) -> None:
        bad = [w for w in self.worlds if w not in WORLD_NAMES]
        if bad or not self.worlds:
            names = ", ".join(bad) or "none"
            raise ConfigError(f"--worlds: {names}; expected some of {', '.join(WORLD_NAMES)}")
        if self.mapping_s >= self.log_s:
            raise ConfigError(
                f"--mapping-s {self.mapping_s}: must be shorter than the log ({self.log_s} s)"
            )

    def world_seed(self, world: str) -> int:
        return self.seed * 10 + WORLD_NAMES.index(world)

    def run_seed(self, world: str, run: int) -> int:
        return 100_000 + self.world_seed(world) * 1000 + run

    def units(self) -> int:
        return len(self.worlds) * (2 + self.runs * len(self.configs))

    def to_dict(self) -> dict[str, Any]:
        return {
            "worlds": list(self.worlds), "configs": [c.name for c in self.configs], "runs": self.runs,
            "seed": self.seed, "log_s": self.log_s, "mapping_s": self.mapping_s, "rate_hz": self.rate_hz,
            "width_px": self.width_px, "height_px": self.height_px,
            "world_seeds": {w: self.world_seed(w) for w in self.worlds},
            "run_seeds": {w: [self.run_seed(w, r) for r in range(self.runs)] for w in self.worlds},
            "time_limit_s": self.tasks.time_limit_s,
        }


@dataclass
class BenchResult:
    settings: BenchSettings
    perception: dict[str, Any] = field(default_factory=dict)  # world -> PerceptionResult
    tasks: list[TaskResult] = field(default_factory=list)
    heatmaps: dict[str, dict[str, Any]] = field(default_factory=dict)  # world -> name -> Heatmap
    navs: dict[str, Any] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)


def run_bench(settings: BenchSettings, out: Path, progress: Progress | None = None) -> BenchResult:
    """Simulate, perceive and run the tasks for every world of ``settings``; logs go to
    ``out/logs/WORLD``."""
    from hiper_cli.bench.nav import NavMap
    from hiper_cli.bench.perception import perceive_configs
    from hiper_cli.bench.search import heatmap_of, points_as_rows
    from hiper_cli.sim import SimConfig, make_world, simulate

    tell = progress or (lambda _what, _n: None)
    result = BenchResult(settings)
    for world_name in settings.worlds:
        seed = settings.world_seed(world_name)
        log = out / "logs" / world_name
        tell(f"{world_name}: simulating {settings.log_s:.0f} s", 0)
        clock = time.perf_counter()
        sim_config = SimConfig.from_flat(
            rate_hz=settings.rate_hz, mapping_s=settings.mapping_s, width_px=settings.width_px,
            height_px=settings.height_px,
        )
        simulate(world_name, settings.log_s, seed, log, sim_config, overwrite=True)
        result.seconds[f"{world_name}/sim"] = time.perf_counter() - clock
        tell(f"{world_name}: perceiving in {len(settings.configs)} configurations", 1)
        clock = time.perf_counter()
        perception = perceive_configs(log, settings.configs)
        result.perception[world_name] = perception
        result.seconds[f"{world_name}/perceive"] = time.perf_counter() - clock
        tell(f"{world_name}: tasks", 1)
        world = make_world(world_name, seed)
        nav = NavMap(world)
        result.navs[world_name] = nav
        kb = perception.knowledge
        maps: dict[str, Any] = {}
        for name in ("C1", "C2"):
            if name in kb:
                k = kb[name]
                maps[f"{name} person"] = heatmap_of(
                    nav, "person", k.person_rows, k.person_track, k.person_speed_mps
                )
                rows, track = points_as_rows(k.bottles)
                maps[f"{name} bottle"] = heatmap_of(nav, "bottle", rows, track, 0.0)
        result.heatmaps[world_name] = {k: v for k, v in maps.items() if v is not None}
        clock = time.perf_counter()
        for run in range(settings.runs):
            for cfg in settings.configs:
                loc = perception.table3[cfg.name]["localisation_classified_m"][0]
                tell(f"{world_name}: run {run + 1}/{settings.runs} {cfg.name}", 0)
                result.tasks.extend(run_episode(
                    nav, kb[cfg.name], cfg, run, settings.run_seed(world_name, run), settings.tasks, loc
                ))
                tell(f"{world_name}: run {run + 1}/{settings.runs} {cfg.name}", 1)
        result.seconds[f"{world_name}/tasks"] = time.perf_counter() - clock
    return result
