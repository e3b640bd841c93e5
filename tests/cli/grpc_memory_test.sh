#!/usr/bin/env bash
# A client that half-sends huge gRPC messages cannot make the server hold them. gRPC buffers a
# message whole before it checks its size against the limit, so two streams that each declare
# 1.5 GB and send it would have the server hold 3 GB; its memory quota for gRPC (start_grpc in
# server/main.cpp) makes gRPC cancel them instead, and the server goes on serving. While memory
# is short gRPC cancels streams it picks without regard to who sent what: a viewer streaming then
# may lose its stream too, and then carries its fluid on locally and hands it back.
# Usage: grpc_memory_test.sh SERVER CLIENT
set -uo pipefail
source "$(dirname "$0")/server_process.sh"
server=$1
client=$2
here=$(dirname "$0")
work=$(mktemp -d)
pid= flood= viewer=
trap 'kill $pid $flood $viewer 2>/dev/null; rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
start_server "$server" "$work"
port=$grpc_port
resident_mb() { awk '/VmRSS/ { print int($2 / 1024) }' "/proc/$pid/status"; }
"$client" --headless --handoff --server "127.0.0.1:$port" --particles 500 --seconds 5 \
  > "$work/viewer.txt" 2>&1 &
viewer=$!
for _ in $(seq 100); do grep -q "streaming from" "$work/viewer.txt" && break; sleep 0.1; done
node "$here/grpc_partial_messages.js" "$port" 1 2 1500000000 > "$work/flood.txt" 2>&1 &
flood=$!
# Until the server has ended both streams, at most 30 s (each line: {"opened":2,"closed":N,...}).
peak=0
for _ in $(seq 120); do
  sleep 0.25
  resident=$(resident_mb)
  ((resident > peak)) && peak=$resident
  tail -1 "$work/flood.txt" | grep -q '"closed":2,' && break
done
last=$(tail -1 "$work/flood.txt" | tr -d '\0')
[[ "$last" == *'"closed":2,'* ]] || fail "the server still holds the half-sent messages: $last"
# Ended by the quota, not at once by something else: the server took over 100 MB of them first.
sent=$(sed -n 's/.*"sent_mb":\([0-9]*\).*/\1/p' <<< "$last")
((${sent:-0} >= 100)) || fail "the streams ended before the server had taken 100 MB: $last"
# Whether the quota cancelled the viewer's stream depends on which streams gRPC picked; when it
# did, the viewer must have counted it as a loss and carried on, not as the server's refusal.
wait $viewer
grep -q "the server ended the stream" "$work/viewer.txt" &&
  fail "the viewer took the quota's cancel for the server's refusal: $(tail -4 "$work/viewer.txt")"
"$client" --headless --server "127.0.0.1:$port" --particles 500 --seconds 1 > "$work/client.txt" 2>&1 ||
  fail "a client could not stream after: $(tail -3 "$work/client.txt")"
if grep -q "continuing locally" "$work/viewer.txt"; then
  echo "the viewer lost its stream to the quota and carried on: $(grep -c 'took the state' "$work/viewer.txt") handback(s)"
else
  echo "the quota did not cancel the viewer's stream this time"
fi
# The quota is 256 MiB; what the server holds besides is under 150 MB.
((peak < 700)) || fail "the server's memory reached $peak MB"
echo "half-sent messages: $last; the server's memory at most $peak MB"
[[ $failures -eq 0 ]] || exit 1
