"""The paper's ablation configurations (Table IV), as switches of hiper's stages and tasks.

C1 is the entire model; each next configuration removes one more part, down to C5, the basic
model of SLAM poses plus the 2D detector (``baseline.project_detections``). What a switch turns
off in perception is in ``perception``; what it changes in the tasks (search by inverse heatmap
or by coverage, learned altitude, heatmap path cost) is in ``tasks``.
"""

from __future__ import annotations

from dataclasses import dataclass

from hiper_cli.errors import ConfigError

__all__ = ["CONFIGS", "BenchConfig", "parse_configs"]


@dataclass(frozen=True)
class BenchConfig:
    """One ablation configuration: which of hiper's parts it keeps."""

    name: str
    label: str
    foreground: bool  # foreground recognition and tracking (else: boxes projected to 3D)
    background: bool  # background recognition (the foreground filters background points)
    heatmaps: bool  # search by the inverse heatmap, people heatmap as path cost
    features: bool  # learned ODS, size and altitude fed back into tracking and search


CONFIGS: dict[str, BenchConfig] = {
    "C1": BenchConfig("C1", "entire model", True, True, True, True),
    "C2": BenchConfig("C2", "without feature learning", True, True, True, False),
    "C3": BenchConfig("C3", "without heatmaps", True, True, False, False),
    "C4": BenchConfig("C4", "without background recognition", True, False, False, False),
    "C5": BenchConfig("C5", "basic model (poses + detector)", False, False, False, False),
}


def parse_configs(text: str | None) -> tuple[BenchConfig, ...]:
    """``"C1,C3"`` -> those configurations (``None``: all five)."""
    if text is None:
        return tuple(CONFIGS.values())
    names = [s.strip().upper() for s in text.split(",") if s.strip()]
    unknown = [n for n in names if n not in CONFIGS]
    if unknown or not names:
        raise ConfigError(f"--configs {text!r}: expected names from {', '.join(CONFIGS)}")
    return tuple(CONFIGS[n] for n in names)
