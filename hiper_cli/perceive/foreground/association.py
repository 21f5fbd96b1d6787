"""Which observation continues which track: assignment rules behind a name.

An assignment takes the (tracks × observations) cost matrix and the mask of pairs the gates
allow, and returns (track index, observation index) pairs, each index at most once, only
allowed ones. ``ForegroundConfig.association`` names the rule (``ASSOCIATIONS``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError

__all__ = ["ASSOCIATIONS", "Assignment", "get_association", "greedy", "hungarian"]

Assignment = Callable[[NDArray[np.float64], NDArray[np.bool_]], list[tuple[int, int]]]

# The cost a forbidden pair gets in the Hungarian problem: far above any gated distance (metres).
FORBIDDEN_COST = 1e6


def hungarian(cost: NDArray[np.float64], allowed: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """The assignment of least total cost (the paper's Hungarian algorithm, scipy)."""
    from scipy.optimize import linear_sum_assignment

    rows, cols = linear_sum_assignment(np.where(allowed, cost, FORBIDDEN_COST))
    return [(int(r), int(c)) for r, c in zip(rows, cols, strict=True) if allowed[r, c]]


def greedy(cost: NDArray[np.float64], allowed: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Cheapest allowed pair first, then the cheapest among the rest (norfair's default)."""
    order = np.argsort(np.where(allowed, cost, np.inf), axis=None, kind="stable")
    used_rows: set[int] = set()
    used_cols: set[int] = set()
    pairs: list[tuple[int, int]] = []
    for flat in order:
        r, c = (int(v) for v in np.unravel_index(flat, cost.shape))
        if not allowed[r, c]:
            break
        if r not in used_rows and c not in used_cols:
            pairs.append((r, c))
            used_rows.add(r)
            used_cols.add(c)
    return sorted(pairs)


ASSOCIATIONS: dict[str, Assignment] = {"hungarian": hungarian, "greedy": greedy}


def get_association(name: str) -> Assignment:
    """The assignment rule registered as ``name``."""
    try:
        return ASSOCIATIONS[name]
    except KeyError:
        known = ", ".join(ASSOCIATIONS)
        raise ConfigError(f"association {name!r}: unknown; expected one of {known}") from None
