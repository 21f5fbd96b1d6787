#!/usr/bin/env bash
# Issue 20's measurements: hiper eval qa on fresh hiper sim logs (and the realistic worlds when
# QA_WORLDS=1) as one benchmark: a line per log with the figures the issue sets targets for,
# and a line `all` over every question of them.
# Usage: scripts/measure_qa.sh OUTDIR [DETECTOR]
# QA_SEEDS (default "house:41 office:42 hospital:43 house:44 office:45"; "" for none), QA_SECONDS (60),
# QA_LOGS (OUTDIR/logs; existing logs are reused).
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
detector="${1:-auto}"
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
logs="${QA_LOGS:-$out/logs}"
targets=()
for spec in ${QA_SEEDS-house:41 office:42 hospital:43 house:44 office:45}; do
  world="${spec%%:*}"; seed="${spec##*:}"; name="${world}_${seed}"
  [ -f "$logs/$name/groundtruth.txt" ] || \
    .venv/bin/hiper sim --world "$world" --seconds "${QA_SECONDS:-60}" --seed "$seed" -o "$logs/$name" \
      --overwrite > /dev/null
  targets+=("$logs/$name")
done
if [ "${QA_WORLDS:-0}" = 1 ]; then
  for dir in "${HIPER_WORLDS:-../shared/worlds}"/*/; do targets+=("${dir%/}"); done
fi
.venv/bin/hiper eval qa "${targets[@]}" -o "$out/qa" --detector "$detector" --json \
  > "$out/qa.json" 2> "$out/qa.err"
.venv/bin/python - "$out/qa.json" <<'PY' | tee "$out/summary.txt"
import json, os, sys
d = json.load(open(sys.argv[1]))
f = lambda v, p: "-" if v is None else format(v, p)
for row in [*d["logs"], {**d, "log": "all"}]:
    print(f"{os.path.basename(row['log']):<14} questions {row['questions']:>4}  binary {f(row['binary_accuracy'], '.3f')}"
          f"  count {f(row['count_accuracy'], '.3f')} ({f(row.get('count_accuracy_glimpses_optional'), '.3f')} glimpses optional)"
          f"  position {f(row['position_error_median_m'], '.3f')} m"
          f"  time {f(row['time_error_median_s'], '.2f')} s  duration {f(row['duration_error_median_s'], '.2f')} s")
PY
