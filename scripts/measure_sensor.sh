#!/usr/bin/env bash
# Issue 54's table: perceive each log (yolox), export it, score it with the worlds' reference
# scorer, time it, and run the detector's ceiling (hiper eval detector) on it.
# Usage: scripts/measure_sensor.sh OUTDIR LOG [LOG ...]   (e.g. ../shared/worlds/* out/degraded/*)
# The scorer is $HIPER_SCORER (default ../shared/tools/eval_scene.py); each LOG needs gt/.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
scorer="${HIPER_SCORER:-../shared/tools/eval_scene.py}"
python="${PYTHON:-.venv/bin/python}"
[ -x "$python" ] || python=/work/main/.venv/bin/python
hiper=("$python" -m hiper_cli)
for log in "$@"; do
  w=$(basename "$log")
  start=$(date +%s.%N)
  PYTHONPATH="$PWD" "${hiper[@]}" perceive "$log" --kb "$out/$w.hiper" --replace --json > "$out/$w.perceive.json"
  end=$(date +%s.%N)
  frames=$(grep -vc '^#' "$log/rgb.txt")
  awk -v w="$w" -v s="$start" -v e="$end" -v n="$frames" \
    'BEGIN { printf "%s: %d frames in %.1f s wall, %.2f frames/s\n", w, n, e - s, n / (e - s) }' > "$out/$w.fps"
  PYTHONPATH="$PWD" "${hiper[@]}" export "$out/$w.json" --kb "$out/$w.hiper" --observations > /dev/null
  "$python" "$scorer" "$log/gt" "$out/$w.json" --json "$out/${w}_m.json" > "$out/${w}_eval.txt" 2>&1
  PYTHONPATH="$PWD" "${hiper[@]}" eval detector "$log" --detector yolox --json > "$out/$w.detector.json"
  cat "$out/$w.fps"
done
