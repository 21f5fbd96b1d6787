"""Run the whole fault suite and write its table: ``python -m tests.faults [--repo DIR] [--docs FILE]``.

``--repo`` measures another checkout (e.g. ``git worktree`` of an older commit); ``--docs``
writes the case -> behaviour table (docs/reliability.md); ``--json`` the outcomes.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict
from pathlib import Path

from tests.faults.corpus import KILL_KINDS, KILLS_PER_KIND, all_cases
from tests.faults.report import write_markdown
from tests.faults.runner import REPO, build_cache, kill_case, run_case, summarise


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repo", type=Path, default=REPO)
    parser.add_argument("--docs", type=Path)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--kills", type=int, default=KILLS_PER_KIND)
    parser.add_argument("--only", default="", help="Run the cases whose name contains this.")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="hiper-faults-") as tmp:
        cache = Path(tmp)
        totals = build_cache(args.repo, cache)
        cases = [c for c in all_cases() if args.only in c.name]
        with ThreadPoolExecutor(args.workers) as pool:
            outcomes = list(pool.map(lambda c: run_case(c, args.repo, cache, totals), cases))
            kills = [(k, i) for k in KILL_KINDS for i in range(args.kills) if args.only in f"kill {k}"]
            outcomes += list(pool.map(lambda ki: kill_case(ki[0], ki[1], args.repo, cache, totals), kills))
    counts = summarise(outcomes)
    for o in outcomes:
        if o.verdict != "pass":
            print(f"{o.verdict:>18}  {o.name}: {o.message} {'; '.join(o.problems)}"[:400])
    print(json.dumps(counts))
    if args.json:
        args.json.write_text(json.dumps({"counts": counts, "outcomes": [asdict(o) for o in outcomes]},
                                        indent=1))
    if args.docs:
        write_markdown(args.docs, outcomes, counts)


if __name__ == "__main__":
    main()
