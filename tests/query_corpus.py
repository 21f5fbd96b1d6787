"""The question corpus (``query_corpus.jsonl``): questions as robotics users type them, each
with the reading a person would expect (or the words hiper should refuse), judged against the
grammar and, on the house truth KB (``query_truth_kb.py``), against the simulator's truth.

Verdicts: ``answered`` (the expected reading, an answer that agrees with the truth where the
reading is simple enough to compute here), ``refused_ok`` (a question outside hiper's scope,
refused naming the expected words), ``refused`` (answerable, refused with a useful message:
the unknown words quoted and a suggestion that parses), ``useless`` (a refusal without
both), ``misread`` (another reading, a wrong answer, or an answer where a refusal was due),
``crash`` (any exception that is not a ``QueryError``).

Run ``python -m tests.query_corpus`` from the repository root to print the shares and every
question that was not answered.
"""

from __future__ import annotations

import json
import math
import re
from collections import Counter
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

from hiper_cli.errors import QueryError
from hiper_cli.query import ask, parse
from hiper_cli.query.geometry import Frustum
from hiper_cli.query.grammar import ParsedQuery
from hiper_cli.query.spec import Near, On, QueryConfig
from tests.query_truth_kb import TruthKb

CORPUS = Path(__file__).with_name("query_corpus.jsonl")
VERDICTS = ("answered", "refused_ok", "refused", "useless", "misread", "crash")


@dataclass
class Outcome:
    question: str
    verdict: str
    detail: str = ""
    truth_checked: bool = False


def load_corpus() -> list[dict[str, Any]]:
    return [json.loads(line) for line in CORPUS.read_text().splitlines() if line.strip()]


def config_of(h: TruthKb) -> QueryConfig:
    w, hgt, fx, fy = (h.camera[k] for k in ("width", "height", "fx", "fy"))
    return QueryConfig(
        frustum=Frustum(
            math.degrees(2 * math.atan(w / 2 / fx)), math.degrees(2 * math.atan(hgt / 2 / fy)), 5.0
        )
    )


def _day_start(now_s: float) -> float:
    return datetime.fromtimestamp(now_s, UTC).replace(hour=0, minute=0, second=0, microsecond=0).timestamp()


def expected_stamp(value: Any, now_s: float) -> float | None:
    """A corpus bound as a stamp: seconds before now, "now", "today", "yesterday", or "HH:MM"
    (that time on the day of now, or the day before when later than now)."""
    if isinstance(value, int | float):
        return now_s - float(value)
    if value == "now":
        return now_s
    if value in ("today", "yesterday"):
        return _day_start(now_s) - (86400.0 if value == "yesterday" else 0.0)
    hour, minute = (int(v) for v in value.split(":"))
    day = datetime.fromtimestamp(_day_start(now_s), UTC)
    stamp = (day + timedelta(hours=hour, minutes=minute)).timestamp()
    return stamp - 86400.0 if stamp > now_s else stamp


def reading_errors(entry: dict[str, Any], parsed: ParsedQuery, now_s: float) -> list[str]:
    """How ``parsed`` differs from the corpus entry's expected reading (empty: the same)."""
    spec, errors = parsed.spec, []

    def check(name: str, got: Any, want: Any) -> None:
        close = isinstance(got, float) and isinstance(want, float) and abs(got - want) < 1e-6
        if got != want and not close:
            errors.append(f"{name}: {got!r} != {want!r}")

    check("answer", parsed.answer, entry["a"])
    classes = entry["c"]
    if classes == ["objects"]:
        check("classes", (spec.classes, spec.layer), ((), "foreground"))
    else:
        check("classes", (set(spec.classes), spec.layer), (set(classes), None))
    near = entry.get("near")
    got_near = None if spec.near is None else Near(spec.near.target, round(spec.near.radius_m, 6))
    check("near", got_near, Near(near[0], float(near[1])) if near else None)
    on = entry.get("on")
    check("on", spec.on, On(on[0], on[1]) if on else None)
    check("in_fov", spec.in_fov, bool(entry.get("fov")))
    check("state", spec.state, entry.get("state"))
    check("change", spec.change, entry.get("change"))
    check("passed", spec.passed_here, bool(entry.get("passed")))
    for bound, got, event in (("since", spec.since_s, parsed.since_event),
                              ("until", spec.until_s, parsed.until_event)):
        want = entry.get(bound)
        if isinstance(want, list):
            check(f"{bound} event", (event.class_name, event.sighting) if event else None, (want[1], want[2]))
        else:
            check(bound, got, None if want is None else expected_stamp(want, now_s))
    check("rank_from", spec.rank_from, entry.get("rank_from"))
    for key, got in (("time_of", parsed.time_of), ("sort", spec.sort), ("limit", spec.limit),
                     ("min_confidence", spec.min_confidence)):
        if key in entry:
            check(key, got, entry[key])
    return errors


def _truth_ids(h: TruthKb, entry: dict[str, Any], now_s: float) -> set[int] | None:
    """The truth instances the expected reading selects, when it is simple enough to compute
    here (classes, a window, a change); None otherwise."""
    if any(k in entry for k in ("near", "on", "fov", "passed", "state", "min_confidence")):
        return None
    since, until = entry.get("since"), entry.get("until")
    if isinstance(since, list) or isinstance(until, list) or entry.get("change") in ("any", "removed"):
        return None if entry.get("change") != "removed" else set()
    lo = expected_stamp(since, now_s) if since is not None else -math.inf
    hi = expected_stamp(until, now_s) if until is not None else now_s
    out = set()
    for tid, stamps in h.seen.items():
        inst = h.truth.instances[tid]
        if entry["c"] == ["objects"] and inst.layer != "foreground":
            continue
        if entry["c"] not in ([], ["objects"]) and inst.class_name not in entry["c"]:
            continue
        if entry.get("change") == "added" and not lo <= stamps[0] <= hi:
            continue
        if entry.get("change") == "moved" and inst.state != "dynamic":
            continue
        if any(lo <= t <= hi for t in stamps):
            out.add(tid)
    return out


def truth_errors(h: TruthKb, entry: dict[str, Any], answer: Any) -> list[str]:
    """How the answer disagrees with the truth (empty when it agrees or cannot be judged here)."""
    ids = _truth_ids(h, entry, answer.now_s)
    if ids is None or entry.get("limit") or entry.get("sort") == "distance":
        return []
    got = {h.id_of(hit.uuid) for hit in answer.hits}
    kind = entry["a"]
    if kind == "count" and answer.count != len(ids):
        return [f"count {answer.count} != truth {len(ids)}"]
    if kind == "yes_no" and answer.value != bool(ids):
        return [f"yes/no {answer.value} != truth {bool(ids)}"]
    if kind == "list" and got != ids:
        return [f"hits {sorted(got)} != truth {sorted(ids)}"]
    if kind in ("location", "time", "goal") and (not got <= ids or bool(got) != bool(ids)):
        return [f"hits {sorted(got)} not among truth {sorted(ids)}"]
    if kind == "time" and ids and entry.get("time_of") in (None, "last", "first") and answer.time is not None:
        first = entry.get("time_of") == "first"
        want = min(h.seen[t][0] for t in ids) if first else max(h.seen[t][-1] for t in ids)
        if abs(answer.time.stamp_s - want) > 1e-6:
            return [f"time {answer.time.stamp_s} != truth {want}"]
    return []


def _refusal_verdict(entry: dict[str, Any], message: str, now_s: float) -> tuple[str, str]:
    quoted = re.findall(r'"([^"]+)"', message.split(" in ", 1)[0])
    suggestion = re.search(r'did you mean "([^"]*)"\?', message)
    try:
        useful = bool(quoted) and suggestion is not None and bool(parse(suggestion.group(1), now_s=now_s))
    except QueryError:
        useful = False
    if "refuse" in entry:
        if useful and set(entry["refuse"]) <= set(quoted):
            return "refused_ok", message
        return ("useless" if not useful else "misread"), message
    return ("refused" if useful else "useless"), message


def judge(entry: dict[str, Any], h: TruthKb | None, kb: Any, now_s: float) -> Outcome:
    """The verdict on one corpus question (``kb`` open on ``h``'s path, or None: reading only)."""
    q = entry["q"]
    envs = kb.environments() if kb is not None else []
    whole = [envs[0].name] if len(envs) == 1 else []  # as ``ask`` reads "in the house"
    try:
        try:
            parsed = parse(q, now_s=now_s, whole_place=whole)
        except QueryError as err:
            verdict, detail = _refusal_verdict(entry, str(err), now_s)
            return Outcome(q, verdict, detail)
        if "refuse" in entry:
            return Outcome(q, "misread", f"answered {parsed.to_dict()}, expected a refusal")
        errors = reading_errors(entry, parsed, now_s)
        checked = False
        if not errors and kb is not None and h is not None:
            answer = ask(kb, q, config=config_of(h))
            errors = truth_errors(h, entry, answer)
            checked = _truth_ids(h, entry, now_s) is not None and not entry.get("limit")
        return Outcome(q, "misread" if errors else "answered", "; ".join(errors), checked)
    except QueryError as err:
        return Outcome(q, "misread", f"answer refused: {err}")
    except Exception as err:
        return Outcome(q, "crash", f"{type(err).__name__}: {err}")


def measure(h: TruthKb) -> list[Outcome]:
    from hiper_cli.graph import open_kb

    with open_kb(h.path) as kb:
        now_s = kb.stamp_span()[1]
        return [judge(entry, h, kb, now_s) for entry in load_corpus()]


def shares(outcomes: list[Outcome]) -> dict[str, float]:
    counts = Counter(o.verdict for o in outcomes)
    return {v: counts[v] / len(outcomes) for v in VERDICTS}


def report(outcomes: list[Outcome]) -> str:
    n = len(outcomes)
    s = shares(outcomes)
    counts = Counter(o.verdict for o in outcomes)
    lines = [f"{n} questions"]
    lines += [f"  {v:<11} {counts[v]:>4}  {100 * s[v]:5.1f} %" for v in VERDICTS]
    lines.append(f"  correct (answered + refused_ok): {100 * (s['answered'] + s['refused_ok']):.1f} %")
    answerable = [o for o, e in zip(outcomes, load_corpus(), strict=True) if "refuse" not in e]
    answered = sum(o.verdict == "answered" for o in answerable)
    lines.append(f"  answered of the {len(answerable)} answerable: {100 * answered / len(answerable):.1f} %; "
                 f"{sum(o.truth_checked for o in outcomes)} answers checked against the truth")
    lines += [f"[{o.verdict}] {o.question} :: {o.detail[:220]}" for o in outcomes
              if o.verdict not in ("answered", "refused_ok")]
    return "\n".join(lines)


if __name__ == "__main__":
    from tests.query_truth_kb import house_truth_kb

    print(report(measure(house_truth_kb())))
