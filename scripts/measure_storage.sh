#!/usr/bin/env bash
# Issue 55's storage figures (docs/results/2026-12-07-bounded-storage.md): knowledge-base bytes
# of the shared bookstore perceived once and again, of a 63 s 30 Hz house, of the first 1, 2,
# 9 and 10 minutes of a 10-minute sim log, and the time `hiper kb compact` takes on 10^6
# observations. Every perceive runs with the default options.
# Usage: scripts/measure_storage.sh OUTDIR [bookstore|house|long|compact ...] (default: all)
# STORAGE_BOOKSTORE (/work/shared/worlds/bookstore), STORAGE_HOUSE (OUTDIR/house63, made by
# hiper sim when absent), STORAGE_LONG (OUTDIR/h600, likewise: 600 s at 2 Hz, seed 11),
# STORAGE_LONG_DETECTOR (truth), STORAGE_OBSERVATIONS (1000000).
set -euo pipefail
cd "$(dirname "$0")/.."
out="$1"; shift
parts="${*:-bookstore house long compact}"
mkdir -p "$out"
export HIPER_MODELS="${HIPER_MODELS:-../shared/models}"
py="${PYTHON:-.venv/bin/python}"
hiper() { PYTHONPATH="$PWD" "$py" -m hiper_cli "$@"; }
size() { PYTHONPATH="$PWD" "$py" scripts/bench_storage.py size "$@"; }
for part in $parts; do
  case "$part" in
    bookstore)
      kb="$out/bookstore.hiper"; rm -rf "$kb"
      hiper perceive "${STORAGE_BOOKSTORE:-/work/shared/worlds/bookstore}" --kb "$kb" --json > "$out/bookstore_1.json"
      size "$kb"
      hiper perceive "${STORAGE_BOOKSTORE:-/work/shared/worlds/bookstore}" --kb "$kb" --again --json \
        > "$out/bookstore_2.json"
      size "$kb" ;;
    house)
      log="${STORAGE_HOUSE:-$out/house63}"
      [ -f "$log/groundtruth.txt" ] || hiper sim --world house --seconds 63 --rate-hz 30 -o "$log" > /dev/null
      kb="$out/house63.hiper"; rm -rf "$kb"
      hiper perceive "$log" --kb "$kb" --json > "$out/house63.json"
      size "$kb" ;;
    long)
      log="${STORAGE_LONG:-$out/h600}"
      [ -f "$log/groundtruth.txt" ] || hiper sim --world house --seconds 600 --rate-hz 2 --seed 11 -o "$log" > /dev/null
      for minutes in 1 2 9 10; do
        rm -rf "$out/long_$minutes" "$out/long_$minutes.hiper"
        PYTHONPATH="$PWD" "$py" scripts/bench_storage.py prefix "$log" $((minutes * 60)) "$out/long_$minutes" > /dev/null
        hiper perceive "$out/long_$minutes" --kb "$out/long_$minutes.hiper" \
          --detector "${STORAGE_LONG_DETECTOR:-truth}" --json > "$out/long_$minutes.json"
        size "$out/long_$minutes.hiper"
      done ;;
    compact)
      kb="$out/synthetic_1m.hiper"
      [ -f "$kb/documents.sqlite" ] || \
        PYTHONPATH="$PWD" "$py" scripts/bench_storage.py fill "$kb" "${STORAGE_OBSERVATIONS:-1000000}"
      PYTHONPATH="$PWD" "$py" scripts/bench_storage.py compact "$kb" ;;
    *) echo "unknown part $part (bookstore, house, long, compact)" >&2; exit 2 ;;
  esac
done
