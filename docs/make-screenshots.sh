#!/usr/bin/env bash
# Regenerate the screenshots in docs/images with the editor's --screenshot mode,
# under Xvfb. Usage: docs/make-screenshots.sh  (set PMVC_EDITOR to use a built binary)
set -euo pipefail
if [[ -z "${PMVC_EDITOR:-}" ]]; then
  cargo build --release
  PMVC_EDITOR="${CARGO_TARGET_DIR:-target}/release/pmvc"
fi
export PMVC_EDITOR_MSAA=4  # smoother lines than the software-adapter default
shoot() { # NAME ARGS...
  local name="$1"; shift
  xvfb-run -a -s "-screen 0 1280x800x24" "$PMVC_EDITOR" edit "$@" --screenshot "docs/images/$name.png" 2>&1 \
    | grep -v XDG_RUNTIME_DIR || true
  echo "docs/images/$name.png"
}
shoot default-scene
shoot first-run --demo
shoot pmvc-posed --pose docs/poses/middle-finger-forward.obj
shoot mvc-posed --method mvc --pose docs/poses/middle-finger-forward.obj
shoot scanned-elephant assets/scan_mesh.obj assets/scan_cage.obj

# The comparison gallery (docs/comparison.md).
finger=docs/poses/middle-finger-forward.obj
shoot compare-side-by-side --pose "$finger" --view side-by-side
shoot compare-heatmap --pose "$finger" --view side-by-side --heatmap 7
shoot compare-heatmap-log --pose "$finger" --view side-by-side --heatmap 7 --log-scale
shoot compare-negativity --pose "$finger" --view side-by-side --negativity
shoot compare-difference --pose "$finger" --view difference
shoot compare-three-families --pose "$finger" --compare mvc,pmvc,harmonic
shoot compare-three-heatmap --pose "$finger" --compare mvc,pmvc,harmonic --heatmap 7 --log-scale
shoot compare-positive-families --pose "$finger" --compare pmvc,mec,mlc,harmonic
shoot compare-grid-and-elastic-families --pose "$finger" --compare bbw,lbc,somigliana,harmonic
bar=$(mktemp -d)
"$PMVC_EDITOR" generate twisted-bar --mesh "$bar/bar.obj" --cage "$bar/bar_cage.obj"
shoot compare-twisted-bar "$bar/bar.obj" "$bar/bar_cage.obj" --pose docs/poses/twisted-bar.obj --compare pmvc,green
elephant=(assets/scan_mesh.obj assets/scan_cage.obj --pose docs/poses/elephant-head-sideways.obj)
shoot compare-elephant-side-by-side "${elephant[@]}" --view side-by-side
shoot compare-elephant-heatmap "${elephant[@]}" --view side-by-side --heatmap 56 --log-scale
shoot compare-elephant-negativity "${elephant[@]}" --view side-by-side --negativity --log-scale
shoot compare-elephant-difference "${elephant[@]}" --view difference
