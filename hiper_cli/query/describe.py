"""``describe``: a compact summary of a scene sized for an LLM prompt (a few hundred words):
layers and counts per class, the time span, recent movers (from the instance index) and the
learned features that ``hiper analyze`` stored (``queries/analyses.rq``; none yet: said so)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiper_cli.clock import is_wall_clock, stamp_text
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query.index import instance_index
from hiper_cli.query.results import TimeValue, ago_text, short_uuid
from hiper_cli.query.templates import template
from hiper_cli.query.vocabulary import counted

__all__ = ["ClassCount", "Description", "describe"]


@dataclass(frozen=True)
class ClassCount:
    layer: str
    class_name: str
    count: int
    first_seen_s: float
    last_seen_s: float
    vacated: int = 0  # of ``count``: those whose place a later session saw empty

    def to_dict(self) -> dict[str, Any]:
        return {
            "layer": self.layer,
            "class": self.class_name,
            "count": self.count,
            "first_seen_s": self.first_seen_s,
            "last_seen_s": self.last_seen_s,
            "vacated": self.vacated,
        }


@dataclass(frozen=True)
class Description:
    kb: str
    environments: tuple[str, ...]
    sessions: int
    span_s: tuple[float, float] | None
    now_s: float
    classes: tuple[ClassCount, ...]
    movers: tuple[dict[str, Any], ...]
    features: tuple[dict[str, Any], ...]

    @property
    def text(self) -> str:
        lines = [
            f"Scene memory {self.kb}: environments {', '.join(self.environments) or 'none'}, "
            f"{self.sessions} session(s)."
        ]
        if self.span_s:
            t0, t1 = self.span_s
            clock = "" if is_wall_clock(t0) else " of log time"
            lines.append(f"Time span {stamp_text(t0)} .. {stamp_text(t1)}{clock} ({t1 - t0:.0f} s); "
                         f"now {stamp_text(self.now_s)}.")
        for layer in ("background", "foreground"):
            parts = [counted(c.count, c.class_name) + (f" ({c.vacated} vacated)" if c.vacated else "")
                     for c in self.classes if c.layer == layer]
            lines.append(f"{layer.capitalize()}: {', '.join(parts) if parts else 'nothing'}.")
        if self.movers:
            lines.append(
                "Recent movers: "
                + "; ".join(
                    f"{m['class']} {short_uuid(m['uuid'])} seen {ago_text(m['last_seen_s'], self.now_s)}"
                    + (f" at {m['speed_mps']:.2f} m/s" if m["speed_mps"] is not None else "")
                    for m in self.movers
                )
                + "."
            )
        else:
            lines.append("Recent movers: none.")
        if self.features:
            lines.append(
                "Learned features: "
                + "; ".join(
                    f"{f['kind']} {f['class']}: "
                    + ", ".join(f"{k} {_short(v)}" for k, v in list(f["values"].items())[:5])
                    for f in self.features[:12]
                )
                + "."
            )
        else:
            lines.append("Learned features: none (run 'hiper analyze features').")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": "hiper-describe",
            "version": 1,
            "kb": self.kb,
            "environments": list(self.environments),
            "sessions": self.sessions,
            "span": None
            if self.span_s is None
            else {
                "first": TimeValue(self.span_s[0], self.now_s).to_dict(),
                "last": TimeValue(self.span_s[1], self.now_s).to_dict(),
            },
            "now": TimeValue(self.now_s, self.now_s).to_dict(),
            "classes": [c.to_dict() for c in self.classes],
            "recent_movers": list(self.movers),
            "features": list(self.features),
            "text": self.text,
        }


def _short(value: Any) -> str:
    return f"{value:.3g}" if isinstance(value, float) else json.dumps(value)[:40]


def describe(kb: KnowledgeBase, *, now_s: float | None = None, recent_s: float = 300.0) -> Description:
    """The summary of ``kb``; movers are dynamic instances seen in the last ``recent_s``."""
    span = kb.stamp_span()
    now = now_s if now_s is not None else (span[1] if span else 0.0)
    prefix = f"urn:hiper:kb:{kb.kb_id}:"
    idx = instance_index(kb)
    groups: dict[tuple[str, str], list[int]] = {}
    for k in range(len(idx)):
        groups.setdefault((str(idx.layers[k]), str(idx.classes[k])), []).append(k)
    classes = tuple(
        sorted(
            (
                ClassCount(
                    layer, name, len(rows), float(idx.first_s[rows].min()), float(idx.last_s[rows].max()),
                    int(np.isfinite(idx.vacated_s[rows]).sum()),
                )
                for (layer, name), rows in groups.items()
            ),
            key=lambda c: (c.layer, -c.count, c.class_name),
        )
    )
    recent = np.flatnonzero((idx.states == "dynamic") & (idx.last_s >= now - recent_s))
    recent = recent[np.argsort(-idx.last_s[recent], kind="stable")][:10]
    movers = tuple(
        {
            "uuid": idx.uuids[k],
            "class": str(idx.classes[k]),
            "last_seen_s": float(idx.last_s[k]),
            "speed_mps": None if np.isnan(idx.speeds[k]) else float(idx.speeds[k]),
        }
        for k in recent
    )
    features = tuple(
        {
            "uuid": r["a"].value.removeprefix("urn:uuid:"),
            "kind": r["kind"].value,
            "class": r["class"].value,
            "t_start_s": float(r["tStart"].value),
            "t_end_s": float(r["tEnd"].value),
            "values": json.loads(r["values"].value),
        }
        for r in kb.query_bound(template("analyses"), {"graphPrefix": prefix})
    )
    return Description(
        kb.location,
        tuple(e.name for e in kb.environments()),
        len(kb.sessions()),
        span,
        now,
        classes,
        movers,
        features,
    )
