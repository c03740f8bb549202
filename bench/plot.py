#!/usr/bin/env python3
"""Charts benchmark results: GPU time against error versus the float64 reference.

Reads Google Benchmark JSON written by glint_bench (--benchmark_out=FILE --benchmark_out_format=json,
with --benchmark_repetitions so that *_median aggregates exist) and draws, for each device file, one
point per method at the chosen size: median GPU time (x) against relative L2 error (y).

    python3 bench/plot.py --size 1920x1080 --out docs/charts/bloom_pareto.svg \
        "H100=docs/perf/bloom_h100.json" "lavapipe=docs/perf/bloom_lavapipe.json"

With --kind occlusion it draws the lens-flare occlusion chart instead: one point per grid size N
of BM_LightCull at --lights lights (automatic path, no per-light results, Hi-Z not timed): median
GPU time (x) against the mean |visible fraction - brute force| (y).

    python3 bench/plot.py --kind occlusion --lights 1000000 --out docs/charts/occlusion_pareto.svg \
        "H100=docs/perf/occlusion_h100.json"
"""
import argparse
import json
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FILTERS = {0: "cod13", 1: "dual", 2: "gauss9"}


def points(path, size):
    """(label, median_us, rel_l2) for every BM_Bloom median at `size` in a benchmark JSON file."""
    w, h = size.split("x")
    out = []
    for b in json.load(open(path))["benchmarks"]:
        if b.get("aggregate_name") != "median" or not b["name"].startswith("BM_Bloom/"):
            continue
        m = re.search(r"w:(\d+)/h:(\d+)/filter:(\d)/fp32:(\d)", b["name"])
        if not m or (m.group(1), m.group(2)) != (w, h) or b.get("rel_l2_vs_f64", -1) < 0:
            continue
        label = FILTERS[int(m.group(3))] + ("/fp32" if m.group(4) == "1" else "/fp16")
        out.append((label, b["median_us"], b["rel_l2_vs_f64"]))
    return out


def occlusion_points(path, lights):
    """(label, median_us, mean_abs_error) for every BM_LightCull grid size at `lights` lights.

    Medians of repetitions are used when present, else the single runs."""
    rows = json.load(open(path))["benchmarks"]
    has_medians = any(b.get("aggregate_name") == "median" for b in rows)
    out = []
    for b in rows:
        if not b["name"].startswith("BM_LightCull/"):
            continue
        if has_medians and b.get("aggregate_name") != "median":
            continue
        if not has_medians and b.get("run_type") == "aggregate":
            continue
        m = re.search(r"n:(\d+)/grid:(\d+)/path:0/results:0/hiz:0", b["name"])
        if not m or int(m.group(1)) != lights:
            continue
        out.append((f"N={m.group(2)}", b["median_us"], b["mean_abs_error_vs_brute_force"]))
    return sorted(out, key=lambda p: int(p[0][2:]))


def main_occlusion(args):
    fig, axes = plt.subplots(1, len(args.inputs), figsize=(5.5 * len(args.inputs), 4.2), squeeze=False)
    for ax, spec in zip(axes[0], args.inputs):
        device, path = spec.split("=", 1)
        pts = occlusion_points(path, args.lights)
        ax.plot([p[1] for p in pts], [p[2] for p in pts], "-o", alpha=0.6)
        for label, us, err in pts:
            ax.annotate(label, (us, err), textcoords="offset points", xytext=(5, 4), fontsize=8)
        ax.set_xscale("log")
        ax.set_xlabel("median GPU time of the cull, us (log)")
        ax.set_ylabel("mean |visible fraction - brute force|")
        ax.set_title(f"occlusion grid, {args.lights} lights, 1920x1080, on {device}")
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out)
    print("wrote", args.out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inputs", nargs="+", help="DEVICE=results.json")
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--out", default="docs/charts/bloom_pareto.svg")
    ap.add_argument("--kind", choices=["bloom", "occlusion"], default="bloom")
    ap.add_argument("--lights", type=int, default=1000000, help="light count of the occlusion chart")
    args = ap.parse_args()
    if args.kind == "occlusion":
        return main_occlusion(args)
    fig, axes = plt.subplots(1, len(args.inputs), figsize=(5.5 * len(args.inputs), 4.2), squeeze=False)
    for ax, spec in zip(axes[0], args.inputs):
        device, path = spec.split("=", 1)
        for label, us, err in points(path, args.size):
            ax.scatter(us, err, s=40)
            ax.annotate(label, (us, err), textcoords="offset points", xytext=(5, 4), fontsize=8)
        ax.set_xscale("log")
        ax.set_xlabel("median GPU time, us (log)")
        ax.set_ylabel("relative L2 error vs float64 reference")
        ax.set_title(f"bloom {args.size} on {device}")
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
