#!/usr/bin/env bash
# Degraded copies of every shared world: each ../shared/worlds/W recorded by a sensor profile
# (hiper convert --degrade), written to OUTDIR/W-PROFILE with its truth in OUTDIR/W-PROFILE/gt.
# Generated, never committed. Usage: scripts/degrade_worlds.sh OUTDIR [PROFILE] [SEED]
# (default structured-light, seed 1). HIPER_WORLDS (default ../shared/worlds) holds the worlds;
# HIPER (default: this checkout's python -m hiper_cli) runs hiper.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: scripts/degrade_worlds.sh OUTDIR [PROFILE] [SEED]" >&2
  exit 2
fi
out="$1"; profile="${2:-structured-light}"; seed="${3:-1}"
worlds="${HIPER_WORLDS:-../shared/worlds}"
python="${PYTHON:-.venv/bin/python}"
[ -x "$python" ] || python=/work/main/.venv/bin/python
read -r -a hiper <<< "${HIPER:-$python -m hiper_cli}"
mkdir -p "$out"
found=0
for dir in "$worlds"/*/; do
  w=$(basename "$dir")
  [ -f "$dir/rgb.txt" ] || [ -f "$dir/associations.txt" ] || continue
  found=1
  start=$(date +%s.%N)
  PYTHONPATH="$PWD" "${hiper[@]}" convert "$dir" "$out/$w-$profile" --degrade "$profile" --seed "$seed" \
    --overwrite --json > "$out/$w-$profile.json"
  end=$(date +%s.%N)
  awk -v w="$w-$profile" -v s="$start" -v e="$end" 'BEGIN { printf "%s: %.1f s\n", w, e - s }'
done
if [ "$found" = 0 ]; then
  echo "$worlds: no TUM logs found; set HIPER_WORLDS to the shared worlds folder" >&2
  exit 1
fi
