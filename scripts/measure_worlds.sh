#!/usr/bin/env bash
# Issue 17's measurements: perceive each realistic world (yolox), export it, score it with the
# worlds' reference scorer and with hiper eval scene; the frame rate of the whole command.
# Usage: scripts/measure_worlds.sh OUTDIR [-o foreground.KEY=VALUE ...]
# HIPER_WORLDS (default ../shared/worlds) holds the worlds, ../shared/tools the scorer.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
worlds="${HIPER_WORLDS:-../shared/worlds}"
scorer="$worlds/../tools/eval_scene.py"
for dir in "$worlds"/*/; do
  w=$(basename "$dir")
  start=$(date +%s.%N)
  .venv/bin/hiper perceive "$worlds/$w" --kb "$out/$w.hiper" --replace "$@" > "$out/$w.log" 2>&1
  end=$(date +%s.%N)
  frames=$(grep -vc '^#' "$worlds/$w/associations.txt")
  awk -v w="$w" -v s="$start" -v e="$end" -v n="$frames" \
    'BEGIN { printf "%s: %d frames in %.1f s wall, %.1f frames/s\n", w, n, e - s, n / (e - s) }' > "$out/$w.fps"
  .venv/bin/hiper export "$out/$w.json" --kb "$out/$w.hiper" --observations > /dev/null 2>&1
  .venv/bin/python "$scorer" "$worlds/$w/gt" "$out/$w.json" --json "$out/${w}_m.json" > "$out/${w}_eval.txt" 2>&1
  .venv/bin/hiper eval scene "$worlds/$w" --kb "$out/$w.hiper" --json > "$out/${w}_scene.json"
  cat "$out/$w.fps"
done
