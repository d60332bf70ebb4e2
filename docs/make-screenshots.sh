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
shoot pmvc-posed --pose docs/poses/middle-finger-sideways.obj
shoot mvc-posed --method mvc --pose docs/poses/middle-finger-sideways.obj
shoot scanned-elephant assets/scan_mesh.obj assets/scan_cage.obj
