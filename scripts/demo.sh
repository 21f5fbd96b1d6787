#!/usr/bin/env bash
# The README's demo: the main job end to end on the built-in example log, into an embedded
# knowledge base (out/demo.hiper), then what it knows, as tables, JSON, a picture and a Rerun
# recording (out/demo.png, out/demo.rrd).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${1:-.venv}"
HIPER="$VENV/bin/hiper"
LOG=fixtures/house_small
KB=out/demo.hiper

# The COCO detector is not shipped (see README): use it when it is found, else the simulator's
# noisy ground-truth detections that the example log carries.
DETECTOR=truth
for dir in "${HIPER_MODELS:-}" models ../shared/models; do
  if [ -n "$dir" ] && [ -f "$dir/yolox_nano/yolox_nano.onnx" ]; then
    DETECTOR=yolox; export HIPER_MODELS="$(cd "$dir" && pwd)"; break
  fi
done
echo "demo: detector '$DETECTOR' (see README, 'The detector model')"

rm -rf "$KB" out/demo.json
mkdir -p out
set -x
"$HIPER" info "$LOG"
"$HIPER" perceive "$LOG" --kb "$KB" --detector "$DETECTOR"
"$HIPER" kb info --kb "$KB"
"$HIPER" kb check --kb "$KB"
"$HIPER" export out/demo.json --kb "$KB"
"$HIPER" view --kb "$KB" --png out/demo.png                 # top-down picture (docs/view.md)
set +x
if "$VENV/bin/python" -c "import rerun" 2>/dev/null; then
  set -x
  "$HIPER" view --kb "$KB" --log "$LOG" -o out/demo.rrd     # open with: rerun out/demo.rrd
else
  echo "demo: no Rerun recording (pip install 'hiper[view]' for out/demo.rrd)"
fi
