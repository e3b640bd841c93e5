# Thin entry points; CMake does the real work (see CMakePresets.json).
PRESET ?= release
JOBS ?= $(shell nproc)
BIN := build/bin

.PHONY: deps build run test bench clean

deps:
	deploy/install-deps.sh

build: deps
	cmake --preset $(PRESET)
	cmake --build --preset $(PRESET) -j $(JOBS)

# The main job: the streaming server, headless, on the best Vulkan device present; it prints where
# to connect and runs until Ctrl-C. Flags and FLUIDCAST_* variables: build/bin/fluidcast-server --help
run: build
	$(BIN)/fluidcast-server

test: build
	ctest --preset $(PRESET) -j $(JOBS)

bench: build
	$(BIN)/fluidcast-bench-cpu
	$(BIN)/fluidcast-bench-gpu
	$(BIN)/fluidcast-bench-render

clean:
	rm -rf build
