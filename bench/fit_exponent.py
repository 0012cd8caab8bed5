#!/usr/bin/env python3
"""Least-squares fit of time = c * unknowns^k (log-log) to bench_scaling's JSON output.

usage: build/bin/bench_scaling --benchmark_out=scaling.json && bench/fit_exponent.py scaling.json
"""
import json
import math
import sys

runs = [b for b in json.load(open(sys.argv[1]))["benchmarks"] if "unknowns" in b]
xs = [math.log(b["unknowns"]) for b in runs]
for key in ("median_step_s", "factorization_s", "peak_memory_MB"):
    ys = [math.log(b[key]) for b in runs]
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    k = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    print(f"{key:16s} grows as unknowns^{k:.2f}")
for b in runs:
    print(f"{int(b['unknowns']):8d} unknowns: step {b['median_step_s']:.3f} s, "
          f"factorisation {b['factorization_s']:.3f} s, peak memory {b['peak_memory_MB']:.0f} MB")
