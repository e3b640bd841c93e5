#!/usr/bin/env bash
# GET /metrics after a streamed session and a refused one: the text passes
# `promtool check metrics` (Prometheus's own lint) and carries the labelled series.
# Usage: metrics_test.sh SERVER CLIENT. Skipped (77) where promtool is not installed.
set -uo pipefail
source "$(dirname "$0")/server_process.sh"
server=$1 client=$2
command -v promtool >/dev/null || { echo "promtool is not installed: skipped"; exit 77; }
work=$(mktemp -d)
pid=
trap 'kill $pid 2>/dev/null; rm -rf "$work"' EXIT
start_server "$server" "$work" --max-particles 5000
grpc=$grpc_port http=$http_port
"$client" --headless --server "127.0.0.1:$grpc" --particles 500 --seconds 1 >/dev/null ||
  { echo "the streamed session failed"; exit 1; }
"$client" --headless --server "127.0.0.1:$grpc" --particles 6000 --seconds 1 >/dev/null 2>&1
node -e 'fetch(process.argv[1]).then((r) => r.text()).then((t) => process.stdout.write(t))' \
  "http://127.0.0.1:$http/metrics" > "$work/metrics.txt" || { echo "GET /metrics failed"; exit 1; }
failures=0
lint=$(promtool check metrics < "$work/metrics.txt" 2>&1) || { echo "promtool: $lint"; failures=1; }
for series in 'fluidcast_build_info{version="' \
              'fluidcast_streams_refused_total{transport="grpc",reason="RESOURCE_EXHAUSTED"} 1' \
              'fluidcast_send_seconds_count{transport="grpc"}' 'fluidcast_device_info{device="' \
              ',index="0",uuid="'; do
  grep -qF "$series" "$work/metrics.txt" || { echo "no series $series"; failures=1; }
done
[[ $failures -eq 0 ]] && echo "/metrics passes promtool" || { head -40 "$work/metrics.txt"; exit 1; }
