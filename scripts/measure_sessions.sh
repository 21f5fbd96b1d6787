#!/usr/bin/env bash
# A lasting memory over several logs of one place: perceive two hiper sim logs of each world
# (their furniture shifted and their small objects moved between seeds) into one knowledge
# base, one environment, and score it (scripts/score_sessions.py).
# Usage: scripts/measure_sessions.sh OUTDIR [-o foreground.KEY=VALUE ...]
# SESSION_PAIRS (default "house:41:71 office:42:72 hospital:43:73"), SESSION_LOGS (OUTDIR/logs;
# existing logs are reused), SESSION_SECONDS (60), SESSION_DETECTOR (yolox).
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
logs="${SESSION_LOGS:-$out/logs}"
for spec in ${SESSION_PAIRS:-house:41:71 office:42:72 hospital:43:73}; do
  IFS=: read -r world first second <<< "$spec"
  kb="$out/$world.hiper"
  rm -rf "$kb"
  for seed in "$first" "$second"; do
    log="$logs/${world}_$seed"
    [ -f "$log/groundtruth.txt" ] || \
      .venv/bin/hiper sim --world "$world" --seconds "${SESSION_SECONDS:-60}" --seed "$seed" -o "$log" \
        --overwrite > /dev/null
    .venv/bin/hiper perceive "$log" --kb "$kb" --env "$world" --detector "${SESSION_DETECTOR:-yolox}" "$@" \
      > "$out/${world}_$seed.log" 2>&1
  done
  .venv/bin/hiper export "$out/$world.json" --kb "$kb" > /dev/null
  echo "== $world $first then $second"
  .venv/bin/python scripts/score_sessions.py "$out/$world.json" "$logs/${world}_$first" "$logs/${world}_$second"
done
