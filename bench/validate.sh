#!/usr/bin/env bash
# The full validation run: fluidcast-validate at its default sizes (dam break a/d = 40, a 10 000
# particle pool), its SVG charts drawn as PNG by Chromium headless, and its summary in
# OUT/summary.txt. Usage: bench/validate.sh [OUT] [fluidcast-validate flags...]
# BIN=.gpu/bin on the GPU machine. Exits as fluidcast-validate does (1: a figure missed its bound).
set -uo pipefail
out=${1:-validation}
shift || true
bin=${BIN:-build/bin}
mkdir -p "$out"
"$bin/fluidcast-validate" --out "$out" "$@" | tee "$out/summary.txt"
status=${PIPESTATUS[0]}
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [[ -n "$browser" ]]; then
  for svg in "$out"/*.svg; do
    "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=800,500 \
      --screenshot="${svg%.svg}.png" "file://$(realpath "$svg")" >/dev/null 2>&1 ||
      echo "validate: could not draw $svg as PNG" >&2
  done
else
  echo "validate: no Chromium found; the charts stay SVG" >&2
fi
exit "$status"
