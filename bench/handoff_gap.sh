#!/usr/bin/env bash
# The handoff gap at a chosen size: a fluidcast-server on spare ports, the window client (under
# Xvfb) streaming from it, the server stopped mid-stream; prints the client's "handoff gap" line
# (last streamed frame to first local frame) for each run.
# Usage: bench/handoff_gap.sh [PARTICLES=5000] [WIDTH=640] [HEIGHT=360] [RUNS=3]
set -euo pipefail
cd "$(dirname "$0")/.."
particles=${1:-5000} width=${2:-640} height=${3:-360} runs=${4:-3}
log=$(mktemp -d)
trap 'rm -rf "$log"' EXIT
for run in $(seq "$runs"); do
  build/bin/fluidcast-server --grpc-port 50071 --http-port 0 >"$log/server" 2>&1 &
  server=$!
  sleep 3
  xvfb-run -a -s '-screen 0 1280x800x24' build/bin/fluidcast-client --server 127.0.0.1:50071 \
    --particles "$particles" --width "$width" --height "$height" --seconds 12 >"$log/client" 2>&1 &
  client=$!
  sleep 7
  kill -TERM "$server"
  wait "$server" || true
  wait "$client" || true
  echo "run $run: $(grep -o 'handoff gap [0-9]* ms' "$log/client" || echo 'no handoff')"
done
