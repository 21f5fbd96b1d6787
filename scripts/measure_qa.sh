#!/usr/bin/env bash
# Issue 20's measurements: hiper eval qa on fresh hiper sim logs (and the realistic worlds when
# QA_WORLDS=1), one line per log with the figures the issue sets targets for.
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
for log in "${targets[@]}"; do
  name=$(basename "$log")
  .venv/bin/hiper eval qa "$log" -o "$out/${name}_qa" --detector "$detector" --json \
    > "$out/$name.json" 2> "$out/$name.err"
  .venv/bin/python - "$out/$name.json" "$name" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
f = lambda v, p: "-" if v is None else format(v, p)
print(f"{sys.argv[2]:<14} questions {d['questions']:>3}  binary {f(d['binary_accuracy'], '.3f')}"
      f"  count {f(d['count_accuracy'], '.3f')} ({f(d.get('count_accuracy_glimpses_optional'), '.3f')} glimpses optional)"
      f"  position {f(d['position_error_median_m'], '.3f')} m"
      f"  time {f(d['time_error_median_s'], '.2f')} s  duration {f(d['duration_error_median_s'], '.2f')} s")
PY
done | tee "$out/summary.txt"
