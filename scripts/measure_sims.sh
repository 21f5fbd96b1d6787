#!/usr/bin/env bash
# Issue 17's measurements on fresh hiper sim logs: simulate each world (kept in LOGS for reuse),
# perceive it, score it with hiper eval scene (and the worlds' reference scorer when present).
# Usage: scripts/measure_sims.sh OUTDIR [DETECTOR] [-o foreground.KEY=VALUE ...]
# SIM_SEEDS (default "house:61 office:62 hospital:63"), SIM_SECONDS (40), SIM_LOGS (OUTDIR/logs).
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
detector="${1:-yolox}"; [ $# -gt 0 ] && shift
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
logs="${SIM_LOGS:-$out/logs}"
scorer="${HIPER_WORLDS:-../shared/worlds}/../tools/eval_scene.py"
for spec in ${SIM_SEEDS:-house:61 office:62 hospital:63}; do
  world="${spec%%:*}"; seed="${spec##*:}"; name="${world}_${seed}"
  [ -f "$logs/$name/gt/instances.json" ] || \
    .venv/bin/hiper sim --world "$world" --seconds "${SIM_SECONDS:-40}" --seed "$seed" -o "$logs/$name" \
      --overwrite > /dev/null
  frames=$(grep -vc '^#' "$logs/$name/rgb.txt")
  start=$(date +%s.%N)
  .venv/bin/hiper perceive "$logs/$name" --kb "$out/$name.hiper" --replace --detector "$detector" "$@" \
    > "$out/$name.log" 2>&1
  end=$(date +%s.%N)
  awk -v w="$name" -v s="$start" -v e="$end" -v n="$frames" \
    'BEGIN { printf "%s: %d frames in %.1f s wall, %.1f frames/s\n", w, n, e - s, n / (e - s) }' > "$out/$name.fps"
  .venv/bin/hiper eval scene "$logs/$name" --kb "$out/$name.hiper" > "$out/${name}_scene.txt"
  .venv/bin/hiper eval scene "$logs/$name" --kb "$out/$name.hiper" --json > "$out/${name}_scene.json"
  if [ -f "$scorer" ]; then
    .venv/bin/hiper export "$out/$name.json" --kb "$out/$name.hiper" --observations > /dev/null 2>&1
    .venv/bin/python "$scorer" "$logs/$name/gt" "$out/$name.json" > "$out/${name}_eval.txt" 2>&1
  fi
  cat "$out/$name.fps"
done
