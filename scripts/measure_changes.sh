#!/usr/bin/env bash
# The change benchmark of issue 55 over seeds and sensors: for each seed and sensor, write
# `hiper sim --sessions 3 --changes 6` (short sessions), perceive the three logs into one
# knowledge base with no --env, and score it with `hiper eval changes` (JSON per run, a table
# at the end by scripts/changes_table.py).
# Usage: scripts/measure_changes.sh OUTDIR
# CHANGE_SEEDS (default "7 8 9 10"), CHANGE_SENSORS ("ideal structured-light"), CHANGE_DETECTORS
# ("truth yolox"), CHANGE_SECONDS (60), CHANGE_RATE_HZ (5). Existing sim folders are reused.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
py="${PYTHON:-.venv/bin/python}"; [ -x "$py" ] || py=python3
hiper() { PYTHONPATH="$PWD" "$py" -m hiper_cli "$@"; }
for seed in ${CHANGE_SEEDS:-7 8 9 10}; do
  for sensor in ${CHANGE_SENSORS:-ideal structured-light}; do
    sim="$out/sim_${sensor}_$seed"
    [ -f "$sim/changes.json" ] || { rm -rf "$sim"; hiper sim --sessions 3 --changes 6 \
      -s "${CHANGE_SECONDS:-60}" --rate-hz "${CHANGE_RATE_HZ:-5}" --seed "$seed" --sensor "$sensor" \
      -o "$sim" > "$sim.log" 2>&1; }
    for det in ${CHANGE_DETECTORS:-truth yolox}; do
      kb="$out/kb_${sensor}_${seed}_$det.hiper"
      rm -rf "$kb"
      for s in 1 2 3; do
        hiper perceive "$sim/session_$s" --kb "$kb" --detector "$det" > "$kb.p$s.log" 2>&1
      done
      hiper eval changes "$sim" --kb "$kb" --json > "$kb.eval.json"
      hiper kb sessions --kb "$kb" > "$kb.sessions.txt"
      echo "== seed $seed sensor $sensor detector $det"
      hiper eval changes "$sim" --kb "$kb"
    done
  done
done
"$py" scripts/changes_table.py "$out"/kb_*.eval.json
