#!/bin/bash
# Run as: xvfb-run -a -s "-screen 0 1280x720x24" docs/viewer_moving_light.sh (needs xdotool).
# Opens the viewer on the default Cornell box with --gi dense, holds the Right arrow (the
# first light moves along +X) for HOLD seconds (default 1.5; the light moves by frame, so
# how far depends on the frame rate), then the viewer saves a screenshot of its 40th
# frame, prints where the light ended up, and exits.
set -u
VOXCONE=${VOXCONE:-target/release/voxcone}
OUT=${OUT:-docs/viewer_moving_light.png}
HOLD=${HOLD:-1.5}
"$VOXCONE" view --size 640x360 --frames 40 --screenshot "$OUT" --validation > "$OUT.log" 2>&1 &
PID=$!
for i in $(seq 1 60); do
  WID=$(xdotool search --name voxcone 2>/dev/null | head -1)
  [ -n "$WID" ] && break
  sleep 1
done
echo "window $WID"
xdotool windowfocus --sync $WID 2>/dev/null || xdotool windowactivate $WID
sleep 3
xdotool keydown Right
sleep "$HOLD"
xdotool keyup Right
wait $PID
status=$?
grep -v INFO "$OUT.log"
echo "exit $status"
