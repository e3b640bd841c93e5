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

# Until the server exists, the main job is the dam break, on the GPU solver when a hardware Vulkan
# device is present (else the CPU solver), printing progress.
run: build
	$(BIN)/fluidcast-sim --scene dam_break --solver pbf --particles 20000 --iterations 4 --until 5 --progress --backend auto

test: build
	ctest --preset $(PRESET) -j $(JOBS)

bench: build
	$(BIN)/fluidcast-bench-cpu
	$(BIN)/fluidcast-bench-gpu
	$(BIN)/fluidcast-bench-render

clean:
	rm -rf build
