#!/usr/bin/env bash
# The frame-loop table: every case of the GPU-time budget's targets (one viewer at 1M, 216k and 64k;
# 8, 32 and 16 viewers with sessions of their own), and one viewer dragging through a 1M pool at
# rest (what a finger in standing water gets, where the first case's fluid is the dam break's most
# violent second), each against a fresh fluidcast-server on
# loopback with the GPU solver, measured by fluidcast-bench-load (fps, latency percentiles,
# simulation speed, GPU ms per frame, server memory). Writes one Markdown file.
# Usage: bench/frame_loop_table.sh [OUT.md] [--smoke]
#   --smoke: the same cases at lavapipe's size (small counts and frames, short runs), to prove the
#   script on a machine without a GPU. BIN (default build/bin) says where the programs are.
#   CASES="5 6" runs only those cases (1-based, in the order below): the first six took over
#   seven minutes on an H100, more than a device call has beside other work.
#   SERVER_FLAGS="--busy-share=0.5" adds flags for every case's server (that one: the solver kept
#   to --sim-share, as issue 13's interactive target counts its GPU time).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-frame-loop.md}
smoke=${2:-}
bin=${BIN:-build/bin}
server_flags=()
for flag in ${SERVER_FLAGS:-}; do server_flags+=("--server-flag=$flag"); done
seconds=20 warm_up=5
# clients width height particles renderer max-growth-MB scene
cases=(
  "1 1920 1080 1000000 auto 256 dam_break"
  "1 1920 1080 216000 auto 256 dam_break"
  "1 1280 720 64000 auto 256 dam_break"
  "8 640 360 64000 auto 256 dam_break"
  "32 640 360 64000 auto 64 dam_break"
  "16 1280 720 216000 auto 256 dam_break"
  "1 1920 1080 1000000 auto 256 pool"
)
if [[ "$smoke" == --smoke ]]; then
  seconds=6 warm_up=3
  cases=(
    "1 320 240 4000 auto 256 dam_break"
    "2 160 120 1000 points 256 dam_break"
    "1 320 240 4000 auto 256 pool"
  )
fi
{
  echo "# Frame loop: $(date -u +%F), commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
  echo
  device=$( (nvidia-smi --query-gpu=name,driver_version --format=csv,noheader ||
              vulkaninfo --summary | grep -m2 -E 'deviceName|driverInfo') 2>/dev/null | tr -s ' \n' ' ')
  echo "Device: ${device:-unknown}"
  echo
  for k in "${!cases[@]}"; do
    [[ -z "${CASES:-}" || " $CASES " == *" $((k + 1)) "* ]] || continue
    read -r clients width height particles renderer growth scene <<<"${cases[$k]}"
    echo "## $clients × ${width}×${height}, $particles particles, $scene, renderer $renderer"
    echo
    echo '```'
    echo "$bin/fluidcast-bench-load --clients $clients --width $width --height $height" \
      "--particles $particles --scene $scene --renderer $renderer --warm-up $warm_up" \
      "--seconds $seconds" \
      "--max-growth-mb $growth --server-flag=--backend=gpu --server-flag=--max-particles=2000000" \
      "${server_flags[@]}"
    echo '```'
    echo
    "$bin"/fluidcast-bench-load --clients "$clients" --width "$width" --height "$height" \
      --particles "$particles" --scene "$scene" --renderer "$renderer" --warm-up "$warm_up" \
      --seconds "$seconds" \
      --max-growth-mb "$growth" --server-flag=--backend=gpu \
      --server-flag=--max-particles=2000000 "${server_flags[@]}" || echo "(exit $?)"
    echo
  done
} | tee "$out"
