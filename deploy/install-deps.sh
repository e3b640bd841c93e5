#!/usr/bin/env bash
# Installs every Debian 12 package that fluidcast's build, tests and run need; with the argument
# `fuzz`, also clang's libFuzzer for `make fuzz`.
# Idempotent: when everything is present it only checks and returns at once.
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build make pkg-config git
  # libraries the code links or includes
  libglm-dev libcli11-dev
  # Vulkan: loader and headers, Mesa's lavapipe (the CPU device CI runs on), validation layer
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  # shaders: compiled and validated at build time
  glslang-tools spirv-tools
  # frames: JPEG through TurboJPEG, PNG for tests and tools
  libturbojpeg0-dev libpng-dev
  # thread pools (Asio), HTTP and WebSocket (Beast), and their TLS (the page's HTTPS)
  libboost-dev libssl-dev
  # structured logs
  libspdlog-dev
  # readiness and stopping for systemd (sd_notify; Type=notify)
  libsystemd-dev
  # the wire protocol: gRPC (health and reflection included) and protobuf
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  # JSON: the headless client's report and gesture scripts
  nlohmann-json3-dev
  # tests and benchmarks (gRPC for Python: the protocol's example client in another language)
  libgtest-dev libgmock-dev libbenchmark-dev python3-grpcio python3-protobuf
  # the native client's window, its overlay's text and font, and a virtual display for its tests
  libsdl2-dev libsdl2-ttf-dev fonts-dejavu-core xvfb xauth
  # the page's local fluid: the C++ solvers compiled to WebAssembly
  emscripten
  # the phone page: npm fetches protobufjs (and playwright-core for the browser test, which drives
  # Debian's Chromium headless)
  nodejs chromium
)
if [[ "${1:-}" == fuzz ]]; then
  packages+=(clang libclang-rt-14-dev)
fi

missing=()
for package in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done

# Debian's nodejs comes without npm; some archives' nodejs includes it.
if ((${#missing[@]} == 0)) && command -v npm >/dev/null && command -v promtool >/dev/null; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if ((EUID != 0)); then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
if ((${#missing[@]} > 0)); then
  echo "install-deps: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
if ! command -v npm >/dev/null; then
  echo "install-deps: installing npm"
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends npm
fi
# promtool, with which a test lints the server's /metrics: Debian ships it in the prometheus package,
# whose installation would also start a Prometheus server, so only the tool is taken out of it.
if ! command -v promtool >/dev/null; then
  echo "install-deps: installing promtool (from Debian's prometheus package) in /usr/local/bin"
  download=$(mktemp -d)
  (cd "$download" && apt-get download -qq prometheus)
  dpkg-deb --fsys-tarfile "$download"/prometheus_*.deb | tar -x -C "$download" ./usr/bin/promtool
  "${sudo_cmd[@]}" install -m 755 "$download/usr/bin/promtool" /usr/local/bin/promtool
  rm -rf "$download"
fi
