#!/usr/bin/env bash
# The README's demo: the main job end to end on the built-in example log.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${1:-.venv}"
HIPER="$VENV/bin/hiper"
LOG=fixtures/house_small
echo "== hiper info $LOG"
"$HIPER" info "$LOG"
