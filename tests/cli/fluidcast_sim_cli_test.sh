#!/usr/bin/env bash
# fluidcast-sim end to end: a short run writes the CSV and PLY it promises, and every bad flag
# gets one line on stderr naming the flag, and exit code 2.
set -uo pipefail
sim="$1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$sim" --scene dam_break --solver pbf --particles 500 --iterations 2 --steps 6 --threads 2 \
  --stats "$work/stats.csv" --dump-every 3 --dump-dir "$work/dumps" > "$work/out.txt" || fail "short run exited $?"
grep -q "kernel radius" "$work/out.txt" || fail "geometry not printed"
head -1 "$work/stats.csv" | grep -q '^step,t,particles,kinetic_energy,max_density_error,avg_density_error,front_x' \
  || fail "CSV header: $(head -1 "$work/stats.csv")"
[[ $(wc -l < "$work/stats.csv") -eq 8 ]] || fail "CSV should have a header and 7 rows"
head -1 "$work/stats.csv" | grep -q ',max_speed,spray,substeps$' || fail "CSV header lacks spray and substeps last"
awk -F, 'NR == 2 && $NF != 0 || NR > 2 && $NF < 1 { bad = 1 } END { exit bad }' "$work/stats.csv" \
  || fail "substeps: 0 before the first step, then at least 1: $(cut -d, -f13 "$work/stats.csv" | tr '\n' ' ')"
for f in step_00000000.ply step_00000003.ply step_00000006.ply; do
  [[ -f "$work/dumps/$f" ]] || fail "missing dump $f"
done
head -c 200 "$work/dumps/step_00000003.ply" | grep -q "element vertex 500" || fail "PLY header"

expect_bad() {
  local pattern="$1"; shift
  "$sim" "$@" > "$work/bad.out" 2> "$work/bad.err"
  local code=$?
  [[ $code -eq 2 ]] || fail "'$*' exited $code, expected 2"
  [[ $(wc -l < "$work/bad.err") -eq 1 ]] || fail "'$*' printed $(wc -l < "$work/bad.err") lines on stderr"
  grep -q -- "$pattern" "$work/bad.err" || fail "'$*' said: $(cat "$work/bad.err")"
}
expect_bad "--scene: unknown scene 'tsunami'" --scene tsunami --steps 1
expect_bad "--solver: unknown solver 'flip'" --solver flip --steps 1
expect_bad "--particles: value -5 is out of range" --particles -5 --steps 1
expect_bad "--particles" --particles 1000000000000 --steps 1
expect_bad "--xsph-viscosity: value nan is not a finite number" --xsph-viscosity nan --steps 1
expect_bad "--time-step: value inf" --time-step inf --steps 1
expect_bad "--steps or --until" --particles 100
expect_bad "--until" --until -1
expect_bad "--iterations" --iterations 0 --steps 1
expect_bad "--column-width" --column-width 5 --steps 1
expect_bad "unknown-flag" --unknown-flag 3 --steps 1
expect_bad "--backend: 'tpu' is not a backend" --backend tpu --steps 1
expect_bad "--device: only with --backend gpu or auto" --device 0 --steps 1
expect_bad "there is no Vulkan device 99; the devices are: 0: " --backend gpu --device 99 --steps 1
# No driver at all (the loader finds no ICD): one sentence naming the package.
VK_ICD_FILENAMES=/nonexistent/icd.json expect_bad "install mesa-vulkan-drivers" --backend gpu --steps 1

# The GPU backend writes the same statistics.
"$sim" --backend gpu --scene dam_break --particles 300 --steps 3 --stats "$work/gpu.csv" \
  > "$work/gpu.txt" 2> "$work/gpu.err" || fail "GPU run exited $?: $(cat "$work/gpu.err")"
[[ "$(head -1 "$work/gpu.csv")" == "$(head -1 "$work/stats.csv")" ]] || fail "GPU CSV header differs"
[[ $(wc -l < "$work/gpu.csv") -eq 5 ]] || fail "GPU CSV should have a header and 4 rows"
grep -q "gpu: using device" "$work/gpu.err" || fail "the chosen device is not logged"

# Rendered frames: one PNG per rendered step (steps 0, 2, 4), of the size asked for.
"$sim" --particles 300 --steps 4 --render "$work/frames" --render-every 2 --width 96 --height 54 \
  > /dev/null 2> "$work/render.err" || fail "render run exited $?: $(cat "$work/render.err")"
[[ $(ls "$work/frames" | wc -l) -eq 3 ]] || fail "expected 3 frames, got: $(ls "$work/frames")"
file "$work/frames/frame_000002.png" 2>/dev/null | grep -q "96 x 54" \
  || head -c 24 "$work/frames/frame_000002.png" | od -An -tx1 | tr -d ' \n' | grep -q "0000006000000036" \
  || fail "frame_000002.png is not a 96×54 PNG"
expect_bad "--renderer: renderer 'raytrace' is not one of: points, ssfr, mc, auto" --renderer raytrace --steps 1
expect_bad "--camera: '1,2' is not yaw,pitch,distance" --camera 1,2 --steps 1
expect_bad "--width, --height: 0×360" --width 0 --steps 1
expect_bad "--ssfr-filter: 'gauss' is not bilateral or narrow" --ssfr-filter gauss --steps 1
expect_bad "--colour-by: 'mass' is not speed or density" --colour-by mass --steps 1
expect_bad "--camera: pitch must be between -89 and 89" --render "$work/bad" --camera 0,120,2 --steps 1

# --video: through ffmpeg where it is installed, else one line saying what to install.
if command -v ffmpeg > /dev/null; then
  "$sim" --particles 300 --steps 4 --video "$work/run.mp4" --width 65 --height 37 \
    > /dev/null 2> "$work/video.err" || fail "video run exited $?: $(cat "$work/video.err")"
  [[ -s "$work/run.mp4" ]] || fail "no video written"
else
  expect_bad "--video: ffmpeg is not installed (apt-get install ffmpeg)" --video "$work/run.mp4" --steps 1
fi

"$sim" --help > /dev/null || fail "--help exited $?"
if ((failures)); then echo "$failures failed"; exit 1; fi
echo "fluidcast-sim CLI: all checks passed"
