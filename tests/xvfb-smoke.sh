#!/usr/bin/env bash
# Smoke test of the real editor binary under Xvfb on a software Vulkan driver:
#  1. `--screenshot` runs: the default scene and the first-run scene bind and a PNG
#     of the window is saved;
#     a scripted run with a missing --pose must exit with status 1;
#     a scripted drag (--drag) moves a handle and reports its frame time, and one
#     of a handle that does not exist exits with status 1;
#  2. an interactive run: xdotool drags across the viewport (orbiting the view, or
#     moving a handle if one is under the cursor), presses M to switch between MVC
#     and PMVC, and the screen is captured after each.
# Needs: xvfb, xdotool, imagemagick (import), mesa-vulkan-drivers.
# Usage: tests/xvfb-smoke.sh [OUT_DIR]   (default: target/smoke)
# Set PMVC_EDITOR to the pmvc binary (default: built here in release mode).
set -euo pipefail

out="${1:-target/smoke}"
mkdir -p "$out"
if [[ -z "${PMVC_EDITOR:-}" ]]; then
  cargo build --release
  PMVC_EDITOR="${CARGO_TARGET_DIR:-target}/release/pmvc"
fi
display=":${PMVC_DISPLAY:-93}"

Xvfb "$display" -screen 0 1280x800x24 >/dev/null 2>&1 &
xvfb_pid=$!
trap 'kill "$xvfb_pid" 2>/dev/null || true' EXIT
sleep 1
export DISPLAY="$display" WAYLAND_DISPLAY=

echo "== screenshot run"
start=$(date +%s)
timeout 300 "$PMVC_EDITOR" edit --screenshot "$out/default-scene.png" 2>"$out/screenshot-run.log" || {
  cat "$out/screenshot-run.log"; exit 1; }
echo "   saved $out/default-scene.png in $(( $(date +%s) - start )) s"
grep "frame time" "$out/screenshot-run.log" || true
test -s "$out/default-scene.png"

echo "== the first-run scene (pmvc alone): MVC, PMVC and their difference"
timeout 300 "$PMVC_EDITOR" edit --demo --screenshot "$out/first-run.png" 2>"$out/first-run.log" || {
  cat "$out/first-run.log"; exit 1; }
test -s "$out/first-run.png"

echo "== a scripted run that fails must say so"
if timeout 300 "$PMVC_EDITOR" edit --pose "$out/no-such-pose.obj" --screenshot "$out/failed-run.png" \
    2>"$out/failed-run.log"; then
  echo "a --screenshot run with a missing --pose exited with status 0" >&2
  cat "$out/failed-run.log"; exit 1
fi
grep -q "no-such-pose.obj" "$out/failed-run.log" || { cat "$out/failed-run.log"; exit 1; }
echo "   exited non-zero, naming the pose file"

echo "== a scripted drag of a handle (--drag), and one of a handle that does not exist"
timeout 300 "$PMVC_EDITOR" edit --screenshot "$out/dragged.png" --drag 0 2>"$out/drag-run.log" || {
  cat "$out/drag-run.log"; exit 1; }
grep "while dragging" "$out/drag-run.log" || { cat "$out/drag-run.log"; exit 1; }
if timeout 300 "$PMVC_EDITOR" edit --screenshot "$out/no-such-handle.png" --drag 9999 \
    2>"$out/no-such-handle.log"; then
  echo "a --screenshot run dragging a handle that does not exist exited with status 0" >&2
  cat "$out/no-such-handle.log"; exit 1
fi
grep -q -- "--drag 9999: the cage has" "$out/no-such-handle.log" || {
  cat "$out/no-such-handle.log"; exit 1; }

echo "== interactive run with an xdotool drag"
"$PMVC_EDITOR" edit >"$out/interactive-run.log" 2>&1 &
editor_pid=$!
window=""
for _ in $(seq 1 60); do
  window=$(xdotool search --name "pmvc editor" 2>/dev/null | head -1 || true)
  [[ -n "$window" ]] && break
  sleep 1
done
if [[ -z "$window" ]]; then
  echo "the editor window did not appear"; cat "$out/interactive-run.log"; exit 1
fi
sleep 3
xdotool mousemove --window "$window" 400 400
sleep 1
import -window root "$out/before-drag.png"
xdotool mousedown 1
for step in $(seq 1 20); do
  xdotool mousemove --window "$window" $((400 + step * 8)) $((400 - step * 3))
  sleep 0.05
done
xdotool mouseup 1
sleep 2
import -window root "$out/after-drag.png"
# M switches the method shown (MVC/PMVC) without rebinding; at least the view's
# label changes.
xdotool windowfocus "$window" 2>/dev/null || true
xdotool key m
sleep 2
import -window root "$out/after-method-switch.png"
kill "$editor_pid" 2>/dev/null || true
wait "$editor_pid" 2>/dev/null || true
test -s "$out/after-drag.png"
echo "   saved $out/after-drag.png"
# The drag must have changed the picture (orbited the view or moved a handle).
changed=$(compare -metric AE "$out/before-drag.png" "$out/after-drag.png" null: 2>&1 || true)
echo "   pixels changed by the drag: $changed"
[[ "${changed%% *}" =~ ^[0-9.e+]+$ ]] && awk "BEGIN { exit !(${changed%% *} > 1000) }" || {
  echo "the drag did not change the view"; exit 1; }
switched=$(compare -metric AE "$out/after-drag.png" "$out/after-method-switch.png" null: 2>&1 || true)
echo "   pixels changed by pressing M: $switched"
[[ "${switched%% *}" =~ ^[0-9.e+]+$ ]] && awk "BEGIN { exit !(${switched%% *} > 50) }" || {
  echo "pressing M did not switch the method shown"; exit 1; }
echo "smoke test passed"
