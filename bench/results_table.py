#!/usr/bin/env python3
"""Turns fluidcast-bench-cpu's JSON (--benchmark_out) into the Markdown table of bench/results."""
import json
import sys

runs = json.load(open(sys.argv[1]))["benchmarks"]
print("| solver | particles | iterations | dt (ms) | substeps/step | steps/s | grid ms | predict ms | solve ms | velocity ms |")
print("|---|---|---|---|---|---|---|---|---|---|")
for r in runs:
    name = r["name"].split("/")
    fields = {}
    for p in name[2:]:
        if ":" in p:
            k, v = p.split(":")
            fields.setdefault(k, v)  # the first "iterations:" is ours, the second Google Benchmark's
    solver = name[0]
    print(f"| {solver} | {fields['particles']} | {fields['iterations'] if solver == 'Pbf' else '–'} | "
          f"{int(fields['dt_us']) / 1000:g} | {r['substeps']:.2f} | {r['steps_per_s']:.1f} | "
          f"{r['grid_ms']:.2f} | {r['predict_ms']:.2f} | {r['solve_ms']:.2f} | {r['velocity_ms']:.2f} |")
