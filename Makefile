# Thin entry points; CMake does the real work (see CMakePresets.json).
PRESET ?= release
JOBS ?= $(shell nproc)
BUILD_DIR := $(if $(filter release,$(PRESET)),build,build/$(PRESET))
BIN := build/bin

.PHONY: deps build run test test-sanitized test-tsan fuzz bench validate clean

deps:
	deploy/install-deps.sh

# Configured once; afterwards the build re-runs CMake itself when a CMakeLists.txt changes.
$(BUILD_DIR)/CMakeCache.txt:
	cmake --preset $(PRESET)

build: deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build --preset $(PRESET) -j $(JOBS)

# The main job: the streaming server, headless, on the best Vulkan device present; it prints where
# to connect and runs until Ctrl-C. Flags and FLUIDCAST_* variables: build/bin/fluidcast-server --help
run: build
	$(BIN)/fluidcast-server

test: build
	ctest --preset $(PRESET) -j $(JOBS)

# The unit, integration and GPU tests built with AddressSanitizer and UndefinedBehaviorSanitizer
# (build/asan; CI runs it after `make test`; the GPU tests on lavapipe, about 5 minutes of it:
# our host code's use of memory around Vulkan, though not its leaks, which Mesa's own leaks would
# drown: leak detection is off for them, and Mesa is not instrumented). Left out: frame-rate
# comparisons, adaptive quality (it reads how late acknowledgements come against the frames'
# pace; it failed once in five runs on two cores), the load test and the bound on a server's memory (the sanitizers slow the server
# several times and hold freed memory in quarantine, which is what those would measure), and the
# descriptor-exhaustion tests: UBSan checks a virtual call's object by writing it to a pipe, which
# it cannot open when the process has no descriptors left, and then reports every such call
# (Boost.System's error_category first) as an invalid vptr. The plain build runs them.
test-sanitized: deps
	cmake --preset asan
	cmake --build --preset asan -j $(JOBS)
	ctest --preset asan -j $(JOBS) -L 'unit|integration|gpu' \
	  -E 'FrameLoopTest|AdaptiveQualityFalls|load_8_clients|DoesNotGrowTheServersMemory|WhenDescriptorsRunOut'

# The server and its integration tests built with ThreadSanitizer (build/tsan; CI runs it after
# test-sanitized): races in our threads. Races inside gRPC, protobuf and lavapipe, which Debian
# ships uninstrumented, are suppressed (tests/sanitizers/tsan.supp); deadlock detection is off
# (lavapipe's LLVM holds more locks at once than TSan's detector tracks). Left out as under
# ASan: frame-rate comparisons, adaptive quality (it reads round trips) and the bound on the
# server's memory.
# The native client's handoff runs here too, with fluids in memory (handoff_stream_test) and
# against the server (handback_test): its threads (connecting, snapshots, the warm local fluid,
# goodbyes) are ours.
TSAN_TESTS := fluidcast-server server_test server_session_test stream_client_test \
  connection_limits_test handoff_stream_test handback_test
test-tsan: deps
	cmake --preset tsan
	cmake --build --preset tsan -j $(JOBS) --target $(TSAN_TESTS)
	ctest --preset tsan -j $(JOBS) -L integration \
	  -E 'FrameLoopTest|WindowClient|load_8_clients|DoesNotGrowTheServersMemory|AdaptiveQualityFalls'
	ctest --preset tsan -j $(JOBS) -R '^HandoffStream\.'

# Coverage-guided fuzzing: each target in tests/fuzz as a libFuzzer program (clang, ASan+UBSan,
# build/fuzz) for FUZZ_SECONDS, from its corpus in tests/fuzz/corpus. New inputs it finds go to
# build/fuzz/corpus, a crashing one to build/fuzz/findings (fix it, then keep the input in the
# target's corpus folder: `make test` replays it from then on). Memory is held to 8 GiB, not
# libFuzzer's 2: session_fuzz's process grows with every input that simulates on the GPU, in the
# Vulkan validation layer (a server made and ended again and again: 4 MB each in the release
# build, none without the layer), and faster under ASan.
FUZZ_SECONDS ?= 60
fuzz:
	deploy/install-deps.sh fuzz
	cmake --preset fuzz
	cmake --build --preset fuzz -j $(JOBS)
	mkdir -p build/fuzz/findings
	for seeds in tests/fuzz/corpus/*/; do \
	  target=$$(basename $$seeds); mkdir -p build/fuzz/corpus/$$target; \
	  build/fuzz/bin/$$target -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=8192 \
	    -artifact_prefix=build/fuzz/findings/$$target- build/fuzz/corpus/$$target $$seeds \
	    || exit 1; \
	done

bench: build
	$(BIN)/fluidcast-bench-cpu
	$(BIN)/fluidcast-bench-gpu
	$(BIN)/fluidcast-bench-render

# The solvers against Martin & Moyce's dam break and a resting pool, full size, with PNG charts
# (Chromium headless draws the SVGs): results in validation/. Options: build/bin/fluidcast-validate --help
validate: build
	bench/validate.sh validation

clean:
	rm -rf build
