#!/usr/bin/env bash
# The README's demo: the main job end to end on the built-in example log, into an embedded
# knowledge base (out/demo.hiper), then what it knows, as tables, JSON, a picture and a Rerun
# recording (out/demo.png, out/demo.rrd), all from this run.
#
# The detector is COCO YOLOX-Nano: found where hiper looks for models, else fetched once
# ('hiper models fetch yolox', verified by sha256, into ~/.cache/hiper/models). Without network
# the demo says so in one line and uses the simulated detections the example log carries.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${1:-.venv}"
HIPER="$VENV/bin/hiper"
LOG=fixtures/house_small
KB=out/demo.hiper

DETECTOR=yolox
where=$("$VENV/bin/python" -c "from hiper_cli.perceive.detect.catalog import locate; print(locate('yolox') or '')")
if [ -n "$where" ]; then
  echo "demo: detector 'yolox' (YOLOX-Nano at $where)"
elif err=$("$HIPER" models fetch yolox --timeout-s 15 2>&1 >/dev/null); then
  echo "demo: detector 'yolox' (YOLOX-Nano, fetched now and verified by 'hiper models fetch yolox')"
else
  DETECTOR=truth
  why=$(printf '%s' "$err" | tr -s '\n' ' ' | sed 's/^ *//; s/ *$//; s/^error: //')
  echo "demo: detector 'truth' (the log's simulated detections), as YOLOX-Nano could not be fetched: $why"
fi

rm -rf "$KB" out/demo.json out/demo.png out/demo.rrd
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
  set +x
else
  echo "demo: no Rerun recording (pip install 'hiper[view]' for out/demo.rrd)"
fi
echo "demo: done with detector '$DETECTOR'; out/demo.png and out/demo.rrd are from this run"
