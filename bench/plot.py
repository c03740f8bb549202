#!/usr/bin/env python3
"""Charts benchmark results: GPU time against error versus the float64 reference.

Reads Google Benchmark JSON written by glint_bench (--benchmark_out=FILE --benchmark_out_format=json,
with --benchmark_repetitions so that *_median aggregates exist) and draws one panel per device file.

--chart bloom (default): one point per bloom filter at the chosen size, median GPU time (x) against
relative L2 error versus the float64 reference (y).

    python3 bench/plot.py --size 1920x1080 --out docs/charts/bloom_pareto.svg \
        "H100=docs/perf/bloom_h100.json" "lavapipe=docs/perf/bloom_lavapipe.json"

--chart blur: the Gaussian blur's speed against accuracy, one series per method, the method
being the benchmark name's prefix BM_Blur<Method> (BM_BlurSeparable/..., BM_BlurDual/...). Each run
with a `rel_l2` counter (relative L2 against the exact Gaussian) is one point: median GPU time (x,
the `median_us` counter or else the run's time) against rel_l2 (log y), labelled with its `sigma`
counter. With --size, only names containing w:W/h:H (or no size at all) are drawn. Medians of
repetitions are used when the file has them, single runs otherwise.

    python3 bench/plot.py --chart blur --size 3840x2160 \
        "H100=docs/perf/blur_h100.json" "lavapipe=docs/perf/blur_lavapipe.json"

--chart occlusion draws the lens-flare occlusion chart instead: one point per grid size N
of BM_LightCull at --lights lights (automatic path, no per-light results, Hi-Z not timed): median
GPU time (x) against the mean |visible fraction - brute force| (y).

    python3 bench/plot.py --chart occlusion --lights 1000000 --out docs/charts/occlusion_pareto.svg \
        "H100=docs/perf/occlusion_h100.json"

--chart object_cull draws the object cull's false positives against its time: one point per
BM_ObjectCull (mixed bounds) and BM_ObjectCullBounds (bounds:1 spheres, bounds:2 boxes) run at
--objects objects: median GPU time of the
whole cull (x) against false_positive_share (y: of the first 4096 objects that brute force finds
hidden, the share the cull keeps). --peer DEVICE=object_cull_torch.json adds the PyTorch peer's
methods (bench/peers/object_cull_torch.py) to the panel of that device. The caption names each
panel's device (from the runs' labels) and --commit (default: git rev-parse --short HEAD).

    python3 bench/plot.py --chart object_cull --out docs/charts/object_cull_fp_time.svg \
        "lavapipe=docs/perf/object_cull_lavapipe.json" "H100=docs/perf/object_cull_h100.json" \
        --peer "H100=docs/perf/object_cull_torch_h100.json"
"""
import argparse
import json
import re
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FILTERS = {0: "cod13", 1: "dual", 2: "gauss9"}


GUARDS = ["off", "karis", "karis_smooth"]


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
        g = re.search(r"guard:(\d)/l0h:(\d+)", b["name"])  # absent in files from before the guard
        if g and g.group(1) != "2":
            label += "/" + GUARDS[int(g.group(1))]
        if g and g.group(2) != "0":
            label += "/l0h" + g.group(2)
        out.append((label, b["median_us"], b["rel_l2_vs_f64"]))
    return out


TIME_TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}


def blur_points(path, size):
    """{method: [(median_us, rel_l2, sigma or None, name)]} for every BM_Blur<Method> run with rel_l2."""
    benchmarks = json.load(open(path))["benchmarks"]
    has_median = any(b.get("aggregate_name") == "median" for b in benchmarks)
    series = {}
    for b in benchmarks:
        m = re.match(r"BM_Blur([A-Za-z0-9]+)", b["name"])
        if not m or "rel_l2" not in b:
            continue
        if has_median and b.get("aggregate_name") != "median":
            continue
        if not has_median and b.get("run_type", "iteration") != "iteration":
            continue
        if size:
            dims = re.search(r"w:(\d+)/h:(\d+)", b["name"])
            if dims and "x".join(dims.groups()) != size:
                continue
        us = b.get("median_us")
        if us is None:
            us = b["real_time"] * TIME_TO_US[b.get("time_unit", "ns")]
        rel = b["rel_l2"]
        if not (rel > 0 and us > 0):  # log axis: a zero error would vanish; skip it loudly
            print(f"skipped {b['name']}: rel_l2 {rel}, time {us} us")
            continue
        series.setdefault(m.group(1), []).append((us, rel, b.get("sigma"), b["name"]))
    return series


def plot_blur(args):
    fig, axes = plt.subplots(1, len(args.inputs), figsize=(6.0 * len(args.inputs), 4.6), squeeze=False)
    markers = "osD^vP*X"
    for ax, spec in zip(axes[0], args.inputs):
        device, path = spec.split("=", 1)
        series = blur_points(path, args.size)
        for i, (method, pts) in enumerate(sorted(series.items())):
            pts.sort()
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=markers[i % len(markers)], linestyle="",
                    label=method)
            for us, err, sigma, _ in pts:
                if sigma is not None:
                    ax.annotate(f"{sigma:g}", (us, err), textcoords="offset points", xytext=(4, 3), fontsize=7)
        times = [p[0] for pts in series.values() for p in pts]
        if times and max(times) / min(times) > 20:
            ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("median GPU time, us")
        ax.set_ylabel("relative L2 error vs exact Gaussian (log)")
        ax.set_title(f"Gaussian blur{' ' + args.size if args.size else ''} on {device} (labels: sigma)")
        ax.grid(True, which="both", alpha=0.3)
        if series:
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out)
    print("wrote", args.out)


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
        m = re.search(r"n:(\d+)/grid:(\d+)/(?:path:0/)?results:0/hiz:0", b["name"])
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


OBJECT_BOUNDS = {0: "mixed (1/4 boxes)", 1: "spheres", 2: "boxes"}


def object_cull_points(path, objects):
    """([(label, median_us, false_positive_share)], device) of the BM_ObjectCull runs at `objects`.

    Medians of repetitions are used when present, else the single runs."""
    rows = json.load(open(path))["benchmarks"]
    has_medians = any(b.get("aggregate_name") == "median" for b in rows)
    out, device = [], ""
    for b in rows:
        if not re.match(r"BM_ObjectCull(Bounds)?/", b["name"]) or "false_positive_share" not in b:
            continue
        if has_medians and b.get("aggregate_name") != "median":
            continue
        if not has_medians and b.get("run_type") == "aggregate":
            continue
        m = re.search(r"objects:(\d+)(?:/bounds:(\d+))?", b["name"])
        if not m or int(m.group(1)) != objects:
            continue
        label = b.get("label", "")
        if " on " in label:
            device = label.split(" on ", 1)[1]
        out.append((OBJECT_BOUNDS[int(m.group(2) or 0)], b["median_us"], b["false_positive_share"]))
    return out, device


def main_object_cull(args):
    commit = args.commit
    if commit is None:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    peers = dict(spec.split("=", 1) for spec in (args.peer or []))
    fig, axes = plt.subplots(1, len(args.inputs), figsize=(6.0 * len(args.inputs), 4.8), squeeze=False)
    captions = []
    markers = "osD^vP*X"
    for ax, spec in zip(axes[0], args.inputs):
        name, path = spec.split("=", 1)
        pts, device = object_cull_points(path, args.objects)
        peer_rows = []
        if name in peers:
            peer_rows = [x for x in json.load(open(peers[name]))["object_cull"] if x["objects"] == args.objects]
        times = [p[1] for p in pts] + [r["median_us"] for r in peer_rows]
        # Milliseconds where the times are long (CPU devices), microseconds otherwise.
        unit, scale = ("ms", 1e-3) if times and max(times) > 1e4 else ("us", 1.0)
        for i, (label, us, fp) in enumerate(pts):
            ax.scatter(us * scale, 100.0 * fp, s=50, marker=markers[i % len(markers)], label=f"glint: {label}")
            ax.annotate(label.split(" ")[0], (us * scale, 100.0 * fp), textcoords="offset points", xytext=(6, 4),
                        fontsize=8)
        for j, r in enumerate(peer_rows):
            ax.scatter(r["median_us"] * scale, 100.0 * r["false_positive_share"], s=50, marker="x", color=f"C{4 + j}",
                       label=f"PyTorch peer: {r['method']} (spheres, own depth)")
        if times and max(times) / min(times) > 20:
            ax.set_xscale("log")
        shares = [100.0 * p[2] for p in pts] + [100.0 * r["false_positive_share"] for r in peer_rows]
        ax.set_ylim(0, 1.2 * max(shares + [0.1]))
        ax.margins(x=0.15)
        ax.set_xlabel(f"median GPU time of the cull, {unit}")
        ax.set_ylabel("false positives, % of brute-force-hidden objects")
        ax.set_title(f"object cull, {args.objects:,} objects, 1920x1080, on {name}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
        captions.append(f"{name}: {device or 'device unknown'}")
    fig.text(0.01, 0.01, "; ".join(captions) + f"; glint commit {commit}", fontsize=7, ha="left", va="bottom")
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(args.out)
    print("wrote", args.out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inputs", nargs="+", help="DEVICE=results.json")
    ap.add_argument("--chart", choices=["bloom", "blur", "occlusion", "object_cull"], default="bloom")
    ap.add_argument("--size", default=None, help="WxH (bloom default 1920x1080; blur default: all sizes)")
    ap.add_argument("--out", default=None, help="default docs/charts/<chart>_pareto.svg")
    ap.add_argument("--lights", type=int, default=1000000, help="light count of the occlusion chart")
    ap.add_argument("--objects", type=int, default=1000000, help="object count of the object_cull chart")
    ap.add_argument("--peer", action="append", help="DEVICE=object_cull_torch.json (object_cull chart)")
    ap.add_argument("--commit", default=None, help="commit named in the object_cull caption")
    args = ap.parse_args()
    if args.out is None:
        args.out = "docs/charts/object_cull_fp_time.svg" if args.chart == "object_cull" else \
            f"docs/charts/{args.chart}_pareto.svg"
    if args.chart == "object_cull":
        return main_object_cull(args)
    if args.chart == "blur":
        plot_blur(args)
        return
    if args.chart == "occlusion":
        return main_occlusion(args)
    if args.size is None:
        args.size = "1920x1080"
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
