#!/usr/bin/env python3
"""Turns the JSON of fluidcast-bench-cpu, -gpu or -render (--benchmark_out) into the Markdown
table of bench/results."""
import json
import sys

everything = json.load(open(sys.argv[1]))["benchmarks"]
# Many sessions (fluidcast-bench-gpu's Sessions/...) have a table of their own, after the rest.
sessions = [r for r in everything if r["name"].startswith("Sessions/")]
# A renderer's construction and first frames (fluidcast-bench-render's NewRenderer...) likewise.
new_renderers = [r for r in everything if r["name"].startswith("NewRenderer")]
runs = [r for r in everything
        if not r["name"].startswith("Sessions/") and not r["name"].startswith("NewRenderer")]


def fields_of(run):
    fields = {}
    for part in run["name"].split("/")[1:]:
        if ":" in part:
            key, value = part.split(":")
            fields.setdefault(key, value)  # the first "iterations:" is ours, the second Google Benchmark's
    return fields


if runs and "frames_per_s" in runs[0]:
    print("| renderer | size | particles | MC nodes | frames/s | MC field | MC triangles | "
          "anisotropy | scene | particles/mesh | smoothing | shading | read-back (GPU ms) | "
          "JPEG encode ms (1 thread) | JPEG KiB | pool encodes/s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    # Encoding from the YCbCr planes the GPU converts, and the surface's roughness, follow.
    for r in runs:
        f = fields_of(r)
        renderer = r['name'].split('/')[0]
        mc = renderer == "Mc"
        nodes = f['mc_nodes'] if f['mc_nodes'] != "0" else "auto"
        nodes = (f"{nodes}³" if f.get("cube") == "1" else f"{nodes} (long side)") if mc else "–"
        print(f"| {renderer} | {f['width']}×{f['height']} | {f['particles']} | "
              f"{nodes} | {r['frames_per_s']:.1f} | "
              f"{r.get('mc_field_ms', 0):.3f} | {r.get('mc_triangles_ms', 0):.3f} | "
              f"{r.get('anisotropy_ms', 0):.3f} | {r['scene_ms']:.3f} | {r['particles_ms']:.3f} | "
              f"{r['smoothing_ms']:.3f} | {r['shading_ms']:.3f} | {r['readback_ms']:.3f} | "
              f"{r['encode_ms']:.2f} | {r['jpeg_kib']:.0f} | {r['pool_encodes_per_s']:.0f} |")
    print()
    print("| renderer | size | particles | planes read-back (GPU ms) | JPEG encode from planes ms | "
          "the same on the pool, in strips ms | rough surface pixels |")
    print("|---|---|---|---|---|---|---|")
    for r in runs:
        f = fields_of(r)
        rough = f"{100 * r['rough_share']:.1f} %" if "rough_share" in r else "–"
        strips = f"{r['pool_planes_encode_ms']:.2f}" if "pool_planes_encode_ms" in r else "–"
        print(f"| {r['name'].split('/')[0]} | {f['width']}×{f['height']} | {f['particles']} | "
              f"{r['planes_readback_ms']:.3f} | {r['planes_encode_ms']:.2f} | {strips} | {rough} |")
elif runs and "gpu_ms" in runs[0]:
    # Stage columns are GPU ms a step (the substeps' sum); the grid is also given a substep, as
    # issue 13's target (≤ 0.10 ms at 1M) counts it.
    print("| solver | particles | iterations | dt (ms) | substeps/step | steps/s | GPU ms/step | "
          "GPU ms/substep | GPU s a simulated s | grid | grid a substep | neighbours | predict | "
          "iterations (each) | vorticity | viscosity |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        f = fields_of(r)
        solver = r["name"].split("/")[0]
        solve = f"{r['solve_ms']:.3f} (forces)"  # the densities come with the neighbour lists
        each = " / ".join(f"{r[k]:.3f}" for k in sorted((k for k in r if k.startswith("iteration") and k.endswith("_ms")), key=lambda k: int(k[9:-3])))
        print(f"| {solver} | {f['particles']} | {f['iterations'] if solver == 'Pbf' else '–'} | "
              f"{int(f['dt_us']) / 1000:g} | {r['substeps']:.2f} | {r['steps_per_s']:.1f} | "
              f"{r['gpu_ms']:.3f} | {r['gpu_ms_per_substep']:.3f} | "
              f"{r['gpu_s_per_simulated_s']:.3f} | {r['grid_ms']:.3f} | "
              f"{r['grid_ms'] / r['substeps']:.3f} | "
              f"{r.get('neighbours_ms', 0):.3f} | {r['predict_ms']:.3f} | {each or solve} | "
              f"{r['velocity_ms']:.3f} | {r['viscosity_ms']:.3f} |")
else:
    print("| solver | particles | iterations | dt (ms) | substeps/step | steps/s | grid ms | neighbours ms | predict ms | solve ms | velocity ms |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        f = fields_of(r)
        solver = r["name"].split("/")[0]
        print(f"| {solver} | {f['particles']} | {f['iterations'] if solver == 'Pbf' else '–'} | "
              f"{int(f['dt_us']) / 1000:g} | {r['substeps']:.2f} | {r['steps_per_s']:.1f} | "
              f"{r['grid_ms']:.2f} | {r.get('neighbours_ms', 0):.2f} | {r['predict_ms']:.2f} | {r['solve_ms']:.2f} | "
              f"{r['velocity_ms']:.2f} |")

if sessions:
    print()
    print("| submissions | sessions × particles | GPU ms per round (all sessions) | wall ms per round |")
    print("|---|---|---|---|")
    for r in sessions:
        f = fields_of(r)
        mode = "one for all" if f["batched"] == "1" else "one per session"
        print(f"| {mode} | {f['sessions']} × {f['particles']} | {r['gpu_ms']:.3f} | {r['wall_ms']:.3f} |")

if new_renderers:
    print()
    print("| new renderer | size | particles | construct ms | first frame ms | warm frame ms |")
    print("|---|---|---|---|---|---|")
    for r in new_renderers:
        f = fields_of(r)
        print(f"| {r['name'].split('/')[0][len('NewRenderer'):]} | {f['width']}×{f['height']} | "
              f"{f['particles']} | {r['construct_ms']:.2f} | {r['first_frame_ms']:.2f} | "
              f"{r['warm_frame_ms']:.2f} |")
