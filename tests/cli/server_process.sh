# Sourced by the command-line tests: a fluidcast-server on loopback with ports of its own.
# start_server SERVER WORK [FLAG...]: starts it with its state in WORK/state and its log in
# WORK/server.txt, waits until it listens, and sets `pid`, `grpc_port` and `http_port`; exits 1
# with its log when it does not start. The caller kills $pid (in its EXIT trap).
start_server() {
  local server=$1 work=$2
  shift 2
  "$server" --listen 127.0.0.1 --grpc-port 0 --http-port 0 --state-dir "$work/state" "$@" \
    > "$work/server.txt" 2>&1 &
  pid=$!
  for _ in $(seq 300); do grep -q "listening: grpc=" "$work/server.txt" && break; sleep 0.1; done
  grpc_port=$(sed -n 's/.*listening: grpc=127.0.0.1:\([0-9]*\).*/\1/p' "$work/server.txt")
  http_port=$(sed -n 's/.*http=127.0.0.1:\([0-9]*\).*/\1/p' "$work/server.txt")
  [[ -n "$grpc_port" && -n "$http_port" ]] ||
    { echo "the server did not start: $(cat "$work/server.txt")"; exit 1; }
}
