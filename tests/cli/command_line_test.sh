#!/usr/bin/env bash
# Every program's command line, one way (common/include/fluidcast/command_line.h): --version
# prints "NAME VERSION" and exits 0; an unknown flag or a value out of range exits 2 with a
# sentence naming it.
set -uo pipefail
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
for program in "$@"; do
  name=$(basename "$program")
  out=$("$program" --version) || fail "$name --version exited $?"
  [[ "$out" =~ ^$name\ [0-9]+\.[0-9]+\.[0-9]+$ ]] || fail "$name --version printed '$out'"
  err=$("$program" --no-such-flag 2>&1 >/dev/null)
  status=$?
  [[ $status -eq 2 ]] || fail "$name --no-such-flag exited $status"
  [[ "$err" == *--no-such-flag* ]] || fail "$name --no-such-flag said '$err'"
done
server=$1
err=$("$server" --max-sessions 0 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *--max-sessions* ]] || fail "--max-sessions 0: exit $status, '$err'"
err=$("$server" --allow-origin evil.example 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *--allow-origin* && "$err" == *scheme://host* ]] ||
  fail "--allow-origin evil.example: exit $status, '$err'"
err=$("$server" --gpu-memory 10 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *--gpu-memory* && "$err" == *"at least 64 MiB"* ]] ||
  fail "--gpu-memory 10: exit $status, '$err'"
# --list-devices: every Vulkan device by the index --device takes, the default marked; a device
# that is not there is refused, naming the ones that are.
out=$("$server" --list-devices 2>&1)
status=$?
[[ $status -eq 0 && "$out" == *$'\n0: '* && "$out" == *"[the default]"* ]] ||
  fail "--list-devices: exit $status, '$out'"
err=$("$server" --device 99 --listen 127.0.0.1 --grpc-port 0 --http-port 0 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *"no Vulkan device 99"* && "$err" == *"0: "* ]] ||
  fail "--device 99: exit $status, '$err'"
# A share that is not a number (CLI11's range check alone lets "nan" through).
for flag in --sim-share --busy-share; do
  err=$("$server" $flag nan 2>&1 >/dev/null)
  status=$?
  [[ $status -eq 2 && "$err" == *$flag* && "$err" == *"not a finite number"* ]] ||
    fail "$flag nan: exit $status, '$err'"
done
# A bad value in a flag's environment variable names the variable.
err=$(FLUIDCAST_GRPC_PORT=abc "$server" 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *FLUIDCAST_GRPC_PORT* ]] || fail "FLUIDCAST_GRPC_PORT=abc: exit $status, '$err'"
# --list-settings prints the defaults whatever the environment holds.
settings=$(FLUIDCAST_GRPC_PORT=abc "$server" --list-settings 2>&1)
status=$?
[[ $status -eq 0 && "$settings" == *"| \`--grpc-port\`"*"50051"* ]] ||
  fail "--list-settings with FLUIDCAST_GRPC_PORT=abc: exit $status, '${settings:0:300}'"
# A second server on a port in use fails to start, saying so, rather than sharing the port.
work=$(mktemp -d)
"$server" --listen 127.0.0.1 --grpc-port 0 --http-port 0 --state-dir "$work/state" \
  --log-format json > "$work/first.txt" 2>&1 &
first=$!
draining=
trap 'kill $first $draining 2>/dev/null; rm -rf "$work"' EXIT
for _ in $(seq 300); do grep -q "listening: grpc=" "$work/first.txt" && break; sleep 0.1; done
port=$(sed -n 's/.*listening: grpc=127.0.0.1:\([0-9]*\).*/\1/p' "$work/first.txt")
if [[ -z "$port" ]]; then
  fail "the first server did not start: $(cat "$work/first.txt")"
else
  err=$("$server" --listen 127.0.0.1 --grpc-port "$port" --http-port 0 --state-dir "$work/state" 2>&1 >/dev/null)
  status=$?
  [[ $status -eq 2 && "$err" == *"in use"* ]] || fail "second server on :$port: exit $status, '$err'"
  # --log-format json: every line an object with a time, a level and a message.
  node -e 'for (const line of require("fs").readFileSync(process.argv[1], "utf8").trim().split("\n")) {
             const o = JSON.parse(line);
             if (!o.time || !o.level || typeof o.message !== "string") throw new Error(line);
           }' "$work/first.txt" || fail "--log-format json: $(head -3 "$work/first.txt")"
fi
# --drain: after SIGTERM /healthz says 503 while the server drains (30 s, longer than a loaded
# machine takes to see it), a second SIGTERM ends the drain, and it exits 0.
"$server" --listen 127.0.0.1 --grpc-port 0 --http-port 0 --state-dir "$work/state" --drain 30 \
  > "$work/drain.txt" 2>&1 &
draining=$!
for _ in $(seq 300); do grep -q "listening: grpc=" "$work/drain.txt" && break; sleep 0.1; done
http=$(sed -n 's/.*http=127.0.0.1:\([0-9]*\).*/\1/p' "$work/drain.txt")
health() { node -e 'fetch(process.argv[1]).then((r) => console.log(r.status), () => console.log("none"))' \
  "http://127.0.0.1:$http/healthz"; }
[[ $(health) == 200 ]] || fail "/healthz before SIGTERM: $(health)"
kill -TERM $draining
answer=none
deadline=$((SECONDS + 15))
while ((SECONDS < deadline)); do answer=$(health); [[ $answer == 503 ]] && break; sleep 0.1; done
[[ $answer == 503 ]] || fail "/healthz while draining: $answer"
grep -q "draining for 30 s" "$work/drain.txt" || fail "no drain said: $(tail -3 "$work/drain.txt")"
sleep 1
kill -0 $draining 2>/dev/null || fail "the server left before its drain was over"
second=$SECONDS
kill -TERM $draining
wait $draining
status=$?
[[ $status -eq 0 ]] || fail "a drained server exited $status"
((SECONDS - second < 15)) || fail "a second SIGTERM did not end the drain ($((SECONDS - second)) s)"
# Where the page's certificate cannot be made or read: one sentence naming it, exit 2.
err=$("$server" --listen 127.0.0.1 --grpc-port 0 --http-port 0 --state-dir /proc/fluidcast 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *"/proc/fluidcast"* ]] || fail "unwritable --state-dir: exit $status, '$err'"
echo "not a certificate" > "$work/bad.pem"
err=$("$server" --listen 127.0.0.1 --grpc-port 0 --http-port 0 --tls-cert "$work/bad.pem" --tls-key "$work/bad.pem" 2>&1 >/dev/null)
status=$?
[[ $status -eq 2 && "$err" == *"bad.pem"* ]] || fail "a bad --tls-cert: exit $status, '$err'"
[[ $failures -eq 0 ]] && echo "all command lines behave" || exit 1
