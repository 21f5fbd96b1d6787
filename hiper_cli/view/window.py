"""The view's time window: the log stamps a ``hiper view`` shows (``--from`` / ``--to``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError

__all__ = ["TimeWindow"]


@dataclass(frozen=True)
class TimeWindow:
    """A closed interval of log stamps in seconds; None leaves that end open."""

    start_s: float | None = None
    end_s: float | None = None

    def __post_init__(self) -> None:
        if self.start_s is not None and self.end_s is not None and self.end_s < self.start_s:
            raise ConfigError(f"--from {self.start_s:g} is after --to {self.end_s:g}; swap them")

    def overlaps(self, first_s: float, last_s: float) -> bool:
        after_start = self.start_s is None or last_s >= self.start_s
        return after_start and (self.end_s is None or first_s <= self.end_s)

    def mask(self, stamps_s: NDArray[np.float64]) -> NDArray[np.bool_]:
        keep = np.ones(len(stamps_s), dtype=bool)
        if self.start_s is not None:
            keep &= stamps_s >= self.start_s
        if self.end_s is not None:
            keep &= stamps_s <= self.end_s
        return keep
