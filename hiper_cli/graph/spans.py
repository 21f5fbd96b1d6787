"""An instance's summarised stretches in view (``data.view_spans``, written by ``compact``):
what the reads turn back into stamps, so "time in view" answers as over the observations."""

from __future__ import annotations

from typing import Any

__all__ = ["VIEW_SPANS", "span_stamps"]

VIEW_SPANS = "view_spans"  # [[first, last], ...] stamps of the stretches in view, summarised


def span_stamps(doc: dict[str, Any], step_s: float = 0.5) -> list[float]:
    """Stamps standing for an instance's summarised stretches in view (``VIEW_SPANS``): each
    stretch from its first to its last stamp in ``step_s`` steps, so "time in view" over them
    is what it was over the observations they summarise."""
    out: list[float] = []
    for a, b in (doc.get("data") or {}).get(VIEW_SPANS, []):
        n = max(1, int((b - a) / step_s))
        out += [a + (b - a) * k / n for k in range(n + 1)]
    return out
