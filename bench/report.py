#!/usr/bin/env python3
"""Markdown tables (and the targets of issues 5 and 8) from the JSON output of the two benchmarks.

usage: bench/report.py indentation.json scaling.json > tables.md
(see bench/README.md for the commands that make the JSON files)
"""
import json
import math
import sys

SECONDS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def load(path):
    runs = {}
    data = json.load(open(path))
    for b in data["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        parts = b["name"].split("/")
        runs[(parts[0], int(parts[1]) if len(parts) > 1 and parts[1].isdigit() else -1)] = b
    return data.get("context", {}), runs


def seconds(b):
    return b["real_time"] * SECONDS[b["time_unit"]]


def fit(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main():
    context, ind = load(sys.argv[1])
    _, sca = load(sys.argv[2]) if len(sys.argv) > 2 else ({}, {})
    get = lambda fam, lvl: ind.get((fam, lvl))
    levels = sorted({lvl for (fam, lvl) in ind if fam == "BM_Assembly"})

    print(f"Measured {context.get('date', '?')} on {context.get('host_name', '?')}: "
          f"{context.get('num_cpus', '?')} CPUs at {context.get('mhz_per_cpu', '?')} MHz.\n")
    for fam, what in (("BM_PickSite", "default meristem"), ("BM_PickSiteRealFlower", "real flower")):
        b = get(fam, -1)
        if b:
            print(f"Picking a site on the {what} (refinement to level {int(b['level'])}, rest state, "
                  f"first contact): {seconds(b):.2f} s ({int(b['vertices'])} vertices, "
                  f"{b['rest_iterations']:.1f} Newton iterations for the rest state).\n")
    maps = [get("BM_MapCellMiddles", j) for j in (1, 2)]
    if all(maps):
        rates = [m["sites_per_s"] for m in maps]
        cells = int(maps[0]["outer_cells"])
        print(f"Stiffness map of the {int(maps[0]['sites'])} cell middles nearest the top at the converged "
              f"default (5 steps to 0.5 µm): {rates[0]:.3f} sites/s with 1 worker, {rates[1]:.3f} with 2 "
              f"({rates[1] / rates[0]:.2f}×; {int(maps[0]['failed'] + maps[1]['failed'])} failed); "
              f"the {cells} outer cells at 2 workers: about {cells / rates[1] / 60:.1f} min "
              f"(issue 14: < 5 min).\n")
    print("| mesh level | unknowns | assembly (ms) | factorisation (ms) "
          "| equilibrium step (ms) | step / factorisation | 50-step curve (s) | × level 0 "
          "| reference curve (s) | speed-up |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    c0 = get("BM_LoadingCurve", 0)
    for lvl in levels:
        a, f = get("BM_Assembly", lvl), get("BM_Factorization", lvl)
        st, c, r = get("BM_EquilibriumStep", lvl), get("BM_LoadingCurve", lvl), get("BM_ReferenceCurve", lvl)
        cells = [str(lvl), f"{int(a['unknowns'])}", f"{1e3 * seconds(a):.1f}", f"{1e3 * seconds(f):.1f}"]
        cells += [f"{st['median_step_ms']:.1f}", f"{st['step_over_factorization']:.2f}"] if st else ["", ""]
        cells += [f"{seconds(c):.2f}", f"{seconds(c) / seconds(c0):.1f}"] if c and c0 else ["", ""]
        ch = get("BM_LoadingCurveHinge", lvl) or c  # the reference runs the hinge model
        cells += [f"{seconds(r):.1f}", f"{seconds(r) / seconds(ch):.0f}×"] if r and ch else ["", ""]
        print("| " + " | ".join(cells) + " |")

    ah = [(lvl, get("BM_Assembly", lvl), get("BM_AssemblyHinge", lvl)) for lvl in levels]
    if all(a and h for _, a, h in ah):
        print("\nAssembly, Koiter bending against the hinge model (issue 11: at most 1.5×): " +
              ", ".join(f"level {lvl} {1e3 * seconds(a):.1f} / {1e3 * seconds(h):.1f} ms = "
                        f"{seconds(a) / seconds(h):.2f}×" for lvl, a, h in ah) + ".")

    c0 = get("BM_LoadingCurveHinge", 0) or c0  # the comparisons below run the hinge model
    c0n = get("BM_LoadingCurveNoPredictor", 0)
    r0, r0p = get("BM_ReferenceCurve", 0), get("BM_ReferenceCurveWithPredictor", 0)
    if c0 and c0n and r0 and r0p:
        print("\nThe unrefined curve, each solver with and without the predictor (each step started "
              "from the polynomial through the last three equilibria, or from the last equilibrium):\n")
        print("| solver | start of a step | curve (s) | iterations or time steps | final force (µN) |")
        print("|---|---|---|---|---|")
        for name, start, b in (("Newton + CHOLMOD", "predictor", c0), ("Newton + CHOLMOD", "last equilibrium", c0n),
                               ("implicit Euler + CG", "predictor", r0p),
                               ("implicit Euler + CG (published)", "last equilibrium", r0)):
            print(f"| {name} | {start} | {seconds(b):.2f} | {int(b['iterations'])} | {b['final_force_uN']:.4f} |")

    if sca:
        runs = [sca[k] for k in sorted(sca)]
        print("\n| unknowns | equilibrium step (s) | factorisation (s) | peak memory (MB) |")
        print("|---|---|---|---|")
        for b in runs:
            print(f"| {int(b['unknowns'])} | {b['median_step_s']:.3f} | {b['factorization_s']:.3f} "
                  f"| {b['peak_memory_MB']:.0f} |")
        xs = [b["unknowns"] for b in runs]
        print("\nFitted exponents (least squares on logarithms): time per equilibrium ∝ unknowns^"
              f"{fit(xs, [b['median_step_s'] for b in runs]):.2f}, factorisation ∝ unknowns^"
              f"{fit(xs, [b['factorization_s'] for b in runs]):.2f}, peak memory ∝ unknowns^"
              f"{fit(xs, [b['peak_memory_MB'] for b in runs]):.2f}.")


if __name__ == "__main__":
    main()
