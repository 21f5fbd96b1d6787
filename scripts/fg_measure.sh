#!/usr/bin/env bash
# Foreground measurements of issue 17: both shared worlds (yolox) and one hiper sim log per world.
# Usage: scripts/fg_measure.sh OUTDIR [-o foreground.KEY=VALUE ...]; prints a summary per log.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-/work/shared/models}"
for w in bookstore warehouse; do
  start=$(date +%s.%N)
  .venv/bin/hiper perceive /work/shared/worlds/$w --kb "$out/$w.hiper" --replace "$@" > "$out/$w.log" 2>&1
  end=$(date +%s.%N)
  frames=$(wc -l < /work/shared/worlds/$w/associations.txt)
  echo "$w wall $(echo "$end - $start" | bc) s for $frames frames" > "$out/$w.fps"
  .venv/bin/hiper export "$out/$w.json" --kb "$out/$w.hiper" --observations > /dev/null 2>&1
  .venv/bin/python /work/shared/tools/eval_scene.py /work/shared/worlds/$w/gt "$out/$w.json" --json "$out/${w}_m.json" > "$out/${w}_eval.txt" 2>&1
done
