#!/usr/bin/env bash
# The server's resident memory after each of N sessions opened, streamed for 3 s and closed, one
# after another (3 s apart, past the server's malloc_trim): memory that keeps growing from cycle
# to cycle is held, not freed. Results: bench/results/memory-cycles-*.md.
#   bench/memory_cycles.sh PARTICLES RENDERER [CYCLES]    e.g. bench/memory_cycles.sh 200000 points 10
set -euo pipefail
cd "$(dirname "$0")/.."
particles=$1 renderer=$2 cycles=${3:-10}
log=$(mktemp)
build/bin/fluidcast-server --grpc-port 0 --http-port 0 --default-particles 1000 >"$log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null; rm -f "$log"' EXIT
for _ in $(seq 50); do grep -q 'grpc=' "$log" && break; sleep 0.2; done
port=$(grep -o 'grpc=[0-9.]*:[0-9]*' "$log" | head -1 | cut -d: -f2)
rss() { awk '/VmRSS/ {print $2}' "/proc/$server/status"; }
echo "start: $(rss) kB"
for k in $(seq "$cycles"); do
  build/bin/fluidcast-client --headless --server "127.0.0.1:$port" --seconds 3 \
    --particles "$particles" --renderer "$renderer" >/dev/null 2>&1
  sleep 3
  echo "cycle $k: $(rss) kB"
done
