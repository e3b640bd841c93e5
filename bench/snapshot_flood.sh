#!/usr/bin/env bash
# A viewer's frame rate and latency while other connections keep calling GetSnapshot on another
# session of the same server (bench/results/snapshot-flood-lavapipe-2026-12-01.md):
#   bench/snapshot_flood.sh [SERVER] [FLOOD]
# SERVER: the server's program (default build/bin/fluidcast-server); FLOOD 0 runs the viewer
# alone. The viewer: `fluidcast-client --headless`, 8000 particles, 16 s; from its 3rd second, 12 s
# of GetSnapshot calls over 16 connections on a session of 100 000 particles
# (bench/snapshot_flood.py). Prints the viewer's figures. Needs Debian's python3-grpcio,
# python3-protobuf and protobuf-compiler-grpc.
set -euo pipefail
cd "$(dirname "$0")/.."
server=${1:-build/bin/fluidcast-server}
flood=${2:-1}
work=$(mktemp -d)
pid=
trap 'kill $pid 2>/dev/null || true; rm -rf "$work"' EXIT
protoc -I proto --python_out="$work" --grpc_python_out="$work" \
  --plugin=protoc-gen-grpc_python=/usr/bin/grpc_python_plugin proto/fluidcast/v1/fluidcast.proto
source tests/cli/server_process.sh
start_server "$server" "$work"
build/bin/fluidcast-client --headless --server "127.0.0.1:$grpc_port" --particles 8000 \
  --seconds 16 --json > "$work/viewer.json" &
viewer=$!
if [[ "$flood" != 0 ]]; then
  sleep 3
  PYTHONPATH="$work" /usr/bin/python3 bench/snapshot_flood.py "127.0.0.1:$grpc_port" 100000 16 12
fi
wait $viewer
/usr/bin/python3 - "$work/viewer.json" <<'END'
import json, sys
d = json.loads(open(sys.argv[1]).read().splitlines()[-1])
print(f"viewer: {d['fps']:.1f} frames/s, latency p50 {d['latency_p50_ms']:.0f} ms, "
      f"p95 {d['latency_p95_ms']:.0f} ms, status {d['status']}")
END
