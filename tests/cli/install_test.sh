#!/usr/bin/env bash
# `cmake --install` into a fresh prefix gives an FHS layout whose server finds its page beside
# its binary (nothing from the source or build tree), and a systemd unit that systemd accepts.
# Usage: install_test.sh BUILD_DIR
set -uo pipefail
build=$1
work=$(mktemp -d)
trap 'kill $pid 2>/dev/null; rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null || { echo "cmake --install failed"; exit 1; }
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
for file in bin/fluidcast-server bin/fluidcast-client bin/fluidcast-sim \
            share/fluidcast/web/index.html share/fluidcast/web/app.js \
            share/fluidcast/web/fluidcast.proto share/fluidcast/web/vendor/protobuf.min.js \
            share/fluidcast/web/wasm/local_fluid.js share/fluidcast/web/wasm/local_fluid_mt.js \
            share/fluidcast/web/wasm/local_fluid_mt.worker.js \
            lib/systemd/system/fluidcast-server.service \
            lib/systemd/system/fluidcast-server@.service; do
  [[ -f "$prefix/$file" ]] || fail "no $file installed"
done
"$prefix/bin/fluidcast-server" --listen 127.0.0.1 --grpc-port 0 --http-port 0 \
  --state-dir "$work/state" > "$work/server.txt" 2>&1 &
pid=$!
for _ in $(seq 300); do grep -q "here: open" "$work/server.txt" && break; sleep 0.1; done
http=$(sed -n 's/.*http=127.0.0.1:\([0-9]*\).*/\1/p' "$work/server.txt")
[[ -n "$http" ]] || fail "the installed server did not start: $(cat "$work/server.txt")"
grep -q "lacks" "$work/server.txt" && fail "the installed page is incomplete: $(grep lacks "$work/server.txt")"
grep -qF "$prefix/bin/fluidcast-client" "$work/server.txt" || fail "the start lines do not name the installed client"
for path in / /app.js /fluidcast.proto /vendor/protobuf.min.js /manifest.webmanifest \
            /wasm/local_fluid.js; do
  status=$(node -e 'fetch(process.argv[1]).then((r) => console.log(r.status), () => console.log("none"))' \
    "http://127.0.0.1:$http$path")
  [[ $status == 200 ]] || fail "GET $path from the installed server: $status"
done
if command -v systemd-analyze >/dev/null; then
  for unit in fluidcast-server.service fluidcast-server@.service; do
    # As installed for this prefix: the unit names the binary by the configured prefix.
    sed "s|^ExecStart=[^ ]*|ExecStart=$prefix/bin/fluidcast-server|" \
      "$prefix/lib/systemd/system/$unit" > "$work/$unit"
    # verify warns of a key it cannot parse and still exits 0: any word from it is a failure.
    out=$(systemd-analyze verify "$work/$unit" 2>&1)
    [[ $? -eq 0 && -z "$out" ]] || fail "systemd-analyze verify $unit: $out"
  done
  grep -qx "ExecStart=$prefix/bin/fluidcast-server --device %i" "$work/fluidcast-server@.service" ||
    fail "the template's instance is not its device: $(grep ExecStart "$work/fluidcast-server@.service")"
else
  echo "systemd-analyze is not installed: the unit is not verified"
fi
[[ $failures -eq 0 ]] && echo "the installation serves the page" || exit 1
