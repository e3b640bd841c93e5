#!/usr/bin/env bash
# The protocol from another language: docs/examples/python_client.py, with modules generated from
# the .proto by Debian's protoc and gRPC plugin, streams a session from the real server, drags
# through it, measures touch-to-photon, saves a JPEG and says goodbye (OK).
# Usage: python_client_test.sh SERVER SOURCE_DIR
set -uo pipefail
source "$(dirname "$0")/server_process.sh"
server=$1
source=$2
python=/usr/bin/python3  # Debian's, with python3-grpcio and python3-protobuf
work=$(mktemp -d)
pid=
trap 'kill $pid 2>/dev/null; rm -rf "$work"' EXIT
protoc -I "$source/proto" --python_out="$work" --grpc_python_out="$work" \
  --plugin=protoc-gen-grpc_python=/usr/bin/grpc_python_plugin \
  "$source/proto/fluidcast/v1/fluidcast.proto" || { echo "protoc failed"; exit 1; }
start_server "$server" "$work"
port=$grpc_port
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
out=$(PYTHONPATH="$work" timeout 120 "$python" "$source/docs/examples/python_client.py" \
  --server "127.0.0.1:$port" --particles 500 --frames 60 --jpeg "$work/last.jpg" 2>&1)
status=$?
echo "$out"
[[ $status -eq 0 ]] || fail "the example exited $status"
[[ "$out" == *"goodbye answered with OK"* ]] || fail "no goodbye"
[[ "$out" =~ over\ ([0-9]+)\ touches && ${BASH_REMATCH[1]} -gt 0 ]] || fail "no touch came back in a frame"
[[ "$(head -c 2 "$work/last.jpg" | od -An -tx1 | tr -d ' ')" == ffd8 ]] || fail "the saved frame is not a JPEG"
# A bad argument is the example's, said as argparse says it.
err=$(PYTHONPATH="$work" "$python" "$source/docs/examples/python_client.py" --frames 5 2>&1 >/dev/null)
[[ $? -eq 2 && "$err" == *--frames* ]] || fail "--frames 5: '$err'"
[[ $failures -eq 0 ]] || exit 1
