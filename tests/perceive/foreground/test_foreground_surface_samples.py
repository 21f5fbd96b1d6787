"""An object's observed surface (``surface_samples.py``): a bounded sample drawn from all its
blobs, early views included, the same on every run."""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.foreground.surface_samples import SAMPLE_POINTS, SurfaceSamples


def _blobs(n):
    """Blob k: 50 points at x = k (one view after another)."""
    return [np.column_stack([np.full(50, float(k)), np.linspace(0, 1, 50), np.zeros(50)]) for k in range(n)]


def test_the_sample_is_bounded_and_spans_all_views():
    samples = SurfaceSamples()
    for blob in _blobs(200):
        samples.add("chair", blob)
    kept = np.array(samples.of("chair"))
    assert kept.shape == (SAMPLE_POINTS, 3)
    xs = kept[:, 0]
    assert xs.min() < 50 and xs.max() >= 150  # early and late views, not only the latest


def test_the_sample_is_the_same_every_run_and_none_for_an_unseen_track():
    a, b = SurfaceSamples(), SurfaceSamples()
    for blob in _blobs(30):
        a.add("table", blob)
        b.add("table", blob)
    assert a.of("table") == b.of("table")
    assert a.of("bottle") is None
    a.add("cup", np.zeros((0, 3)))
    assert a.of("cup") is None
