"""The statistics of feature learning: the folded-normal noise of standing objects and
bootstrap confidence intervals (paper VI-A), vectorised over numpy columns."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["bootstrap_mean_ci", "folded_normal_sigma", "truncated_second_moment"]

FloatArray = NDArray[np.float64]
_CHUNK_DRAWS = 2_000_000  # indices drawn per block of bootstrap resamples (16 MB)


def truncated_second_moment(k_sigmas: float) -> float:
    """E[z² | |z| < k] for a standard normal z: the share of σ² that the speeds below kσ keep."""
    phi = math.exp(-0.5 * k_sigmas**2) / math.sqrt(2.0 * math.pi)
    mass = math.erf(k_sigmas / math.sqrt(2.0))
    return 1.0 - 2.0 * k_sigmas * phi / mass


def folded_normal_sigma(
    speeds_mps: FloatArray,
    k_sigmas: float,
    min_sigma_mps: float,
    max_sigma_mps: float = math.inf,
    iterations: int = 100,
) -> float:
    """σ of the stationary portion of speeds |v| ~ |N(0, σ²)| mixed with faster motion.

    Fixed point of σ² = mean(|v|² over |v| < kσ) / E[z² | |z| < k]: the speeds below the
    threshold are the noise, corrected for the part of the folded normal the threshold cuts
    off. Started from the sample's 5th percentile (the noise if at least a twentieth of the
    rows stand), it grows onto the lowest mode; ``min_sigma_mps`` floors it (exact zeros) and
    ``max_sigma_mps`` caps it: a class that never stands (the hospital's walkers) has no noise
    mode, and its walking speeds must not be taken for one.
    """
    v = np.asarray(speeds_mps, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return float(min_sigma_mps)
    share = truncated_second_moment(k_sigmas)
    v2 = np.sort(v) ** 2
    cum = np.concatenate([[0.0], np.cumsum(v2)])
    # start below the noise: the 5th percentile of |N(0, σ²)| is 0.0627 σ; the fixed point
    # iteration then grows onto the lowest mode (from above it would swallow the motion)
    sigma = float(np.sqrt(v2[int(0.05 * (v2.size - 1))])) / 0.0627
    sigma = min(max(sigma, min_sigma_mps), max_sigma_mps)
    for _ in range(iterations):
        n = int(np.searchsorted(v2, (k_sigmas * sigma) ** 2, side="left"))
        if n == 0:
            break
        new = min(max(float(np.sqrt(cum[n] / n / share)), min_sigma_mps), max_sigma_mps)
        if abs(new - sigma) <= 1e-9 * max(sigma, 1e-12):
            sigma = new
            break
        sigma = new
    return sigma


def bootstrap_mean_ci(
    values: FloatArray,
    groups: NDArray[np.int64] | None = None,
    *,
    level: float = 0.95,
    samples: int = 1000,
    seed: int = 0,
) -> tuple[float, float, float]:
    """(mean, lo, hi): the mean of ``values`` and its percentile bootstrap CI at ``level``.

    With ``groups`` (one id per value: the track a trajectory row belongs to) whole groups are
    resampled, so rows of one track, which are far from independent, count as one draw.
    """
    x = np.asarray(values, dtype=np.float64)
    if x.size == 0:
        return math.nan, math.nan, math.nan
    rng = np.random.default_rng(seed)
    alpha = (1.0 - level) / 2.0
    if groups is None:
        sums, counts = x, np.ones_like(x)
    else:
        _, inverse = np.unique(np.asarray(groups), return_inverse=True)
        sums = np.bincount(inverse, weights=x).astype(np.float64)
        counts = np.bincount(inverse).astype(np.float64)
    n = sums.size
    means = np.empty(samples)
    step = max(1, _CHUNK_DRAWS // n)  # resamples per block: bounded memory
    for start in range(0, samples, step):
        k = min(step, samples - start)
        draws = rng.integers(0, n, size=(k, n))
        means[start : start + k] = sums[draws].sum(axis=1) / counts[draws].sum(axis=1)
    lo, hi = np.quantile(means, [alpha, 1.0 - alpha])
    return float(x.mean()), float(lo), float(hi)
