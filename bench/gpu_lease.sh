#!/usr/bin/env bash
# Everything a session measures on a lent GPU machine, in parts that each fit one device call
# (10 minutes) and bring back at most a few files. Build here first, then bundle what it runs:
#   ../shared/tools/gpu-bundle build $(bench/gpu_lease.sh programs)
# and on the device (carry .gpu):  source .gpu/env.sh && BIN=.gpu/bin bench/gpu_lease.sh PART W
# A build here is for x86-64-v3 (AVX2, FMA: FLUIDCAST_X86_64_V3), which every H100/H200 host runs.
# A device call brings back at most 8 files from $OUT: run the parts into a folder W outside it
# (e.g. /tmp/w/PART) and pack it after each part, `tar czf $OUT/all.tgz -C /tmp/w .`, so that a
# part cut off by its timeout still leaves the earlier ones (bench/results/h200-2026-11-28.md).
# PART: programs  the programs the parts run (for the bundle), on standard output
#       tests   the devices (fluidcast-server --list-devices beside nvidia-smi -L), every GPU
#               test with the validation layer on (a message fails its test), then
#               session_fuzz (clients' streams into a hub on the device, added 2026-11-30: its
#               corpus from this tree, and 3 s of mutations; last, so that a part cut off at its
#               timeout loses only it). The golden images and gpu_solver_inputs_test's corpus
#               are read where the source tree was at the build (here /work/main): link them
#               there first, `mkdir -p /work/main/tests &&
#               ln -sfn $PWD/tests/golden /work/main/tests/golden &&
#               ln -sfn $PWD/tests/fuzz /work/main/tests/fuzz`
#       solver  fluidcast-bench-gpu: what the driver says of each pass's code (pipelines.txt:
#               registers and the like, added 2026-11-29), the solver table (dt = 1 ms, and a
#               session's 1/120 s at 216k and 1M: GPU s a simulated s, added 2026-11-29, a few s
#               more) and many sessions batched against serial
#       render  fluidcast-bench-render: passes, encode from RGBA and from planes, roughness; and
#               the dam break at 216k and 1M, t = 0.5 s, with spheres and ellipsoids, as PNG
#               (for docs/images: ssfr-ellipsoids-216k.png, -1m.png)
#       tiles   the variant with cells in bricks and shared-memory tiles (built here first with
#               bench/build_variant.sh tiles bench/results/gpu-tiles-2026-11-30.patch, bundled as
#               fluidcast-bench-gpu-tiles and gpu_solver_test-tiles): its solver tests with the
#               validation layer, what the driver says of its passes, then the 216k and 1M dam
#               break at 4 iterations and 32 × 64k, with tiles and without
#               (FLUIDCAST_TILE_SHARED_BYTES=0: cells in bricks alone)
#       loop    the frame-loop table (bench/frame_loop_table.sh; on an H100 over 7 minutes: give
#               CASES="1 2 3" and CASES="4 5 6" a call each; case 7, a finger in a 1M pool at rest,
#               came after the H200's lease; SERVER_FLAGS="--busy-share=0.5" keeps the solver
#               to --sim-share, as issue 13's interactive target counts it)
#       validate  the validation against Martin & Moyce and the resting pool at 1M
#       lease   what the next lease needs most, in one device call, each part under a timeout
#               of its own: tests, solver, the tiles variant (when
#               BIN/fluidcast-bench-gpu-tiles is there), the frame loop's cases 1 and 7 and the
#               same kept to --sim-share, case 5 (32 viewers), burst, validate (not render, nor
#               the loop's other cases). W is packed into PACK (e.g. PACK=$OUT/all.tgz) after
#               each part, so a call cut off at its limit still brings back every part before.
#               At most 585 s, about 480 s at the H200's 2026-11-28 times.
#       burst   whether the 1M dam break still bursts (it did on an H100 on 2026-11-25, before
#               the corrections' velocity cap and the rule's wait for fresh figures):
#               fluidcast-sim to t = 0.5 s (its substeps, centre of mass height, largest speed
#               and share of spray at the end: the H200's frames showed a cloud of spray on
#               2026-11-28) at 216k to 2M; at 1M with 2 and 8 iterations, without the density
#               bound on substeps (--pbf-density-tolerance 0.1), without the cap, with every
#               iteration's corrections in full (--pbf-jacobi-damping 0), with statistics
#               read back every step, and as point frames. The CPU solver's 1M reference is in
#               bench/results/h100-2026-11-25.md (centre of mass 0.114 m high at t = 0.5 s)
# Times on an H100 (2026-11-25): tests 43 s, solver 12 s (with 2 and 6 iterations; the rows at 4
# came later), render 27 s. On an H200 (2026-11-28): tests 50 s, solver 12 s, render 14–16 s,
# loop CASES="1 5" 78 s and "2 3 4 6" 105 s, validate 75 s, burst over 90 s. Each writes its log
# and tables under OUT. --smoke (third argument) runs the benchmarks' small cases, to prove the
# script here on lavapipe.
set -euo pipefail
cd "$(dirname "$0")/.."
gpu_tests=(gpu_context_test gpu_neighbour_grid_test gpu_solver_test gpu_step_batch_test
  solver_inputs_test gpu_solver_inputs_test render_test render_golden_test render_surface_test ssfr_splat_test
  anisotropy_test default_size_test timestamps_test)
programs=(fluidcast-server fluidcast-sim fluidcast-validate fluidcast-bench-gpu
  fluidcast-bench-render fluidcast-bench-load fluidcast-bench-soak "${gpu_tests[@]}" session_fuzz)
usage="usage: bench/gpu_lease.sh programs|tests|solver|tiles|render|loop|validate|burst|lease OUT [--smoke]"
part=${1:?$usage}
if [[ "$part" == programs ]]; then
  # and the tiles variant, where bench/build_variant.sh has built it
  for variant in fluidcast-bench-gpu-tiles gpu_solver_test-tiles; do
    [[ -x build/bin/$variant ]] && programs+=("$variant")
  done
  echo "${programs[@]}"
  exit 0
fi
out=${2:?$usage}
smoke=${3:-}
bin=${BIN:-build/bin}
mkdir -p "$out"
smoke_flag=()
[[ "$smoke" == --smoke ]] && smoke_flag=(--smoke)

table() {  # JSON of a benchmark program into its Markdown table
  bench/results_table.py "$1" >"${1%.json}.md" || echo "no table from $1" >&2
}

case "$part" in
  tests)
    status=0
    # The devices as the server lists them, and as NVIDIA's tool does: whether Vulkan's deviceUUID
    # is the UUID nvidia-smi prints (docs/operations.md, Many GPUs, says so; added 2026-12-01).
    { "$bin/fluidcast-server" --list-devices; nvidia-smi -L; } >"$out/devices.txt" 2>&1 || true
    cat "$out/devices.txt"
    for test in "${gpu_tests[@]}"; do
      echo "== $test" >>"$out/tests.log"
      FLUIDCAST_VALIDATION=1 "$bin/$test" >>"$out/tests.log" 2>&1 || status=1
    done
    # Clients' streams into a hub on this device, its corpus then 3 s of mutations.
    echo "== session_fuzz" >>"$out/tests.log"
    if ! "$bin/session_fuzz" tests/fuzz/corpus/session_fuzz --seconds 3 >>"$out/tests.log" 2>&1
    then
      status=1
      cp fuzz-failure-session_fuzz "$out/" || true  # the input that failed, to replay here
    fi
    grep -E "^\[  (PASSED|FAILED)|validation|^session_fuzz" "$out/tests.log" || true
    exit $status
    ;;
  solver)
    # What the driver says of each pass's code (registers: how many invocations a multiprocessor
    # keeps in flight), in a run of its own: the timings do not depend on its capture.
    "$bin/fluidcast-bench-gpu" --pipeline-statistics --benchmark_filter=none 2>&1 |
      tee "$out/pipelines.log" | grep -E '^(pipeline|gpu:)' | tee "$out/pipelines.txt" || true
    "$bin/fluidcast-bench-gpu" "${smoke_flag[@]}" --benchmark_out="$out/bench-gpu.json" \
      --benchmark_out_format=json 2>&1 | tee "$out/bench-gpu.log"
    table "$out/bench-gpu.json"
    ;;
  render)
    "$bin/fluidcast-bench-render" "${smoke_flag[@]}" --benchmark_out="$out/bench-render.json" \
      --benchmark_out_format=json 2>&1 | tee "$out/bench-render.log"
    table "$out/bench-render.json"
    if [[ "$smoke" != --smoke ]]; then
      for particles in 216000 1000000; do
        for shape in spheres ellipsoids; do
          "$bin/fluidcast-sim" --backend gpu --particles "$particles" --until 0.5 \
            --render "$out/frames-$particles-$shape" --render-every 60 --renderer ssfr \
            --ssfr-particles "$shape" --camera 30,35,1.9 --width 1280 --height 720 2>&1 | tail -1
        done
      done
    fi
    ;;
  tiles)
    # The tiles variant (bench/results/gpu-tiles-2026-11-30.md), built apart: its solver tests
    # with the validation layer (shared memory and barriers lavapipe cannot prove), what the
    # driver says of its passes, then the rows to compare with main's, with tiles and without.
    status=0
    FLUIDCAST_VALIDATION=1 "$bin/gpu_solver_test-tiles" >"$out/tests.log" 2>&1 || status=1
    grep -E "^\[  (PASSED|FAILED)|validation|workgroups" "$out/tests.log" || true
    "$bin/fluidcast-bench-gpu-tiles" --pipeline-statistics --benchmark_filter=none 2>&1 |
      grep -E '^(pipeline|gpu:)' | tee "$out/pipelines.txt" || true
    filter='Pbf/dam_break/particles:(216000|1000000)/iterations:4/dt_us:1000/|Sessions/batched/sessions:32/particles:64000/'
    [[ "$smoke" == --smoke ]] && filter='Pbf/dam_break/particles:4000/iterations:4/'
    for shared in device 0; do
      (if [[ "$shared" != device ]]; then export FLUIDCAST_TILE_SHARED_BYTES=$shared; fi
       "$bin/fluidcast-bench-gpu-tiles" "${smoke_flag[@]}" --benchmark_filter="$filter" \
         --benchmark_out="$out/bench-gpu-tiles-$shared.json" --benchmark_out_format=json 2>&1 |
         tee "$out/bench-gpu-tiles-$shared.log")
      table "$out/bench-gpu-tiles-$shared.json"
    done
    exit $status
    ;;
  loop)
    BIN="$bin" bench/frame_loop_table.sh "$out/frame-loop.md" "$smoke" 2>&1 | tail -20
    ;;
  validate)
    if [[ "$smoke" == --smoke ]]; then
      BIN="$bin" bench/validate.sh "$out/validation" --backend gpu --column-resolution 8 \
        --pool-particles 1000 2>&1 | tail -5
    else
      BIN="$bin" bench/validate.sh "$out/validation" --backend gpu --column-resolution 100 \
        --pool-particles 1000000 2>&1 | tail -5
    fi
    ;;
  burst)
    sim() {  # NAME FLAGS...: one run to t = 0.5 s and its last line (substeps, centre of mass,
      local name=$1  # largest speed, spray)
      shift
      local status=0
      # --foreground: within the process group of a timeout around the whole part (lease), which
      # then stops this run too rather than leave it on the GPU beside the next part.
      timeout --foreground 90 "$bin/fluidcast-sim" --backend gpu --until "${until:-0.5}" "$@" \
        >"$out/$name.log" 2>&1 || status=$?
      echo "$name (exit $status): $(tail -1 "$out/$name.log")"
    }
    counts=(216000 500000 1000000 2000000)
    big=1000000
    [[ "$smoke" == --smoke ]] && counts=(2000 4000) big=4000 until=0.05
    for n in "${counts[@]}"; do sim "p$n" --particles "$n" --max-particles 2000000; done
    sim "p$big-it2" --particles "$big" --iterations 2
    sim "p$big-it8" --particles "$big" --iterations 8
    sim "p$big-no-density-bound" --particles "$big" --pbf-density-tolerance 0.1
    sim "p$big-uncapped" --particles "$big" --pbf-max-acceleration 100000
    sim "p$big-undamped" --particles "$big" --pbf-jacobi-damping 0
    # Statistics read back every step, so that the substep rule sees each step's compression
    # before planning the next (no steps in flight), as on the CPU.
    sim "p$big-synchronous" --particles "$big" --stats "$out/p$big-synchronous.csv"
    sim "p$big-frames" --particles "$big" --render "$out/frames" --render-every 15 \
      --renderer points --camera 30,35,1.9 --width 960 --height 540
    ;;
  lease)
    pack=${PACK:?"PACK: the archive to pack $out into after each part, e.g. PACK=\$OUT/all.tgz"}
    step() {  # SECONDS NAME COMMAND...: one part under its timeout, its output in NAME.log
      local seconds=$1 name=$2
      shift 2
      echo "== $name: at most $seconds s, from $(date +%T)"
      local status=0
      timeout -k 5 "$seconds" "$@" >"$out/$name.log" 2>&1 || status=$?
      echo "$name: exit $status$([[ $status == 124 ]] && echo ' (cut off by its timeout)')"
      tail -4 "$out/$name.log"
      # Whole or not at all: a call cut off while packing keeps the archive of the part before.
      tar czf "$pack.partial" -C "$out" . && mv "$pack.partial" "$pack" || echo "pack: failed"
    }
    self=bench/gpu_lease.sh
    # The timeouts add up to 585 s, within a device call's 600; on an H200 the parts took about
    # 440 s in all (tests 50, solver 12, the loop 39 a case, burst over 90, validate 75), and the
    # tiles part should take about 40 (a solver test program and two short tables).
    step 70 tests "$self" tests "$out/tests" "$smoke"
    step 45 solver "$self" solver "$out/solver" "$smoke"
    if [[ -x "$bin/fluidcast-bench-gpu-tiles" ]]; then
      step 60 tiles "$self" tiles "$out/tiles" "$smoke"
    fi
    step 95 loop-1-7 env -u SERVER_FLAGS CASES="1 7" "$self" loop "$out/loop-1-7" "$smoke"
    step 95 loop-1-7-sim-share env CASES="1 7" SERVER_FLAGS="--busy-share=0.5" \
      "$self" loop "$out/loop-1-7-sim-share" "$smoke"
    step 55 loop-5 env -u SERVER_FLAGS CASES="5" "$self" loop "$out/loop-5" "$smoke"
    step 80 burst "$self" burst "$out/burst" "$smoke"
    step 85 validate "$self" validate "$out/validate" "$smoke"
    ;;
  *)
    echo "bench/gpu_lease.sh: PART must be tests, solver, tiles, render, loop, validate, burst or lease, not '$part'" >&2
    exit 2
    ;;
esac
