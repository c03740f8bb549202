#!/usr/bin/env python3
"""Charts benchmark results: GPU time against error versus the float64 reference.

Reads Google Benchmark JSON written by glint_bench (--benchmark_out=FILE --benchmark_out_format=json,
with --benchmark_repetitions so that *_median aggregates exist) and draws, for each device file, one
point per method at the chosen size: median GPU time (x) against relative L2 error (y).

    python3 bench/plot.py --size 1920x1080 --out docs/charts/bloom_pareto.svg \
        "H100=docs/perf/bloom_h100.json" "lavapipe=docs/perf/bloom_lavapipe.json"
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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inputs", nargs="+", help="DEVICE=results.json")
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--out", default="docs/charts/bloom_pareto.svg")
    args = ap.parse_args()
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
