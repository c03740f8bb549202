#!/usr/bin/env python3
"""Charts for docs/: benchmark results (GPU time against error versus the float64 reference) and
the firefly stability data.

Reads Google Benchmark JSON written by glint_bench (bench/chart_data.sh writes one file per chart:
medians of 3 repetitions) and draws one panel per DEVICE=FILE argument. Every panel's title names
its device (from the runs' labels), the glint commit and the date of the run: the commit is the
JSON context's glint_commit (bench/chart_data.sh records it), or --commit NAME=COMMIT for a file
that lacks it (--commit COMMIT applies to every panel). Panels of one chart share their axis scales.
Add --png to also write a PNG next to the SVG (to look at it).

--chart bloom (default): one point per bloom configuration (filter, level precision, firefly
guard, level0_height) at --size (default 1920x1080): median GPU time (x) against relative L2 error
versus the float64 reference (y). Configurations are told apart by marker and colour in one legend.

    python3 bench/plot.py --chart bloom --out docs/charts/bloom_pareto.svg \
        "H100=docs/perf/bloom_h100.json" "lavapipe=docs/perf/bloom_lavapipe.json"

--chart blur: the Gaussian blur's speed against accuracy, one line per method, the method being the
benchmark name's prefix BM_Blur<Method> (BM_BlurSeparable/..., BM_BlurDual/...). Each run with a
`rel_l2` counter (relative L2 against the exact Gaussian) is one point: median GPU time (x, the
`median_us` counter, log) against rel_l2 (y, log); the marker's fill gives sigma (a colour bar).
With --size, only names containing w:W/h:H (or no size at all) are drawn; without it each panel
draws its file's largest size.

    python3 bench/plot.py --chart blur --out docs/charts/blur_pareto.svg \
        "H100=docs/perf/blur_h100.json" "lavapipe=docs/perf/blur_lavapipe.json"

--chart occlusion: one point per grid size N of BM_LightCull (automatic path, no per-light results,
Hi-Z not timed) at --lights lights (default: the most lights in each file): median GPU time of
the cull (x, log) against the mean |visible fraction - brute force| (y, log), one line for the
default multi-jittered pattern (pattern:0) and points for the regular grid (pattern:1) when the
file has them. Runs from before the pattern argument are drawn as "pattern not recorded".

    python3 bench/plot.py --chart occlusion --out docs/charts/occlusion_pareto.svg \
        "H100=docs/perf/occlusion_h100.json" "lavapipe=docs/perf/occlusion_lavapipe.json"

--chart object_cull draws the object cull's false positives against its time: one point per
BM_ObjectCull (mixed bounds) and BM_ObjectCullBounds (bounds:1 spheres, bounds:2 boxes) run at
--objects objects: median GPU time of the whole cull (x) against false_positive_share (y: of the
first 4096 objects that brute force finds hidden, the share the cull keeps). --peer
DEVICE=object_cull_torch.json adds the PyTorch peer's methods (bench/peers/object_cull_torch.py)
to the panel of that device.

    python3 bench/plot.py --chart object_cull --out docs/charts/object_cull_fp_time.svg \
        "lavapipe=docs/perf/object_cull_lavapipe.json" "H100=docs/perf/object_cull_h100.json" \
        --peer "H100=docs/perf/object_cull_torch_h100.json"

--chart firefly draws docs/stability/ from what build/bench/glint_stability_report writes
(firefly_energy.json, firefly_frames_raw.png): firefly_energy.png, the bloom energy of every frame
of the moving 1e4 point relative to that configuration's mean over its 64 frames, one line per
filter and guard (max_brightness 1000), the whole range and a zoom on +-3%; and
firefly_frames.png, the frames of the raw filmstrip with their frame number, point position and
guard. Each argument is one report's directory, DIR or DEVICE=DIR (without DEVICE the panel is
named by the JSON's "device"). One directory: the whole range and the zoom side by side, both
charts written into that directory (or --out-dir, or --out FILE for the energy chart and the
frames beside it).
Several: one column per device (top the whole range, bottom the zoom, each panel titled with its
device and commit, one legend below giving each line's spread on every device) and one filmstrip
block per device stacked vertically, written into --out-dir (default docs/stability). The report
does not record the commit: give --commit NAME=COMMIT per device (NAME as the panel is named) or a
bare --commit COMMIT for all; a panel without either is captioned with git rev-parse --short HEAD.

    # one device (lavapipe)
    python3 bench/plot.py --chart firefly --commit COMMIT docs/stability
    # both devices: the H100's report in docs/stability/h100, lavapipe's in docs/stability
    python3 bench/plot.py --chart firefly --out-dir docs/stability \
        --commit H100=COMMIT_H100 --commit lavapipe=COMMIT_LAVAPIPE \
        "H100=docs/stability/h100" "lavapipe=docs/stability"
"""
import argparse
import json
import math
import os
import re
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

TIME_TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
MARKERS = "osD^vP*Xh<>p"


# ---------------------------------------------------------------------------------------------
# Shared: reading runs, captions, time units


class Run:
    """One benchmark JSON file: its medians (or single runs), device and commit."""

    def __init__(self, name, path, commits):
        data = json.load(open(path))
        self.name = name
        self.path = path
        self.context = data.get("context", {})
        rows = data["benchmarks"]
        has_medians = any(b.get("aggregate_name") == "median" for b in rows)
        if has_medians:
            self.rows = [b for b in rows if b.get("aggregate_name") == "median"]
        else:
            self.rows = [b for b in rows if b.get("run_type", "iteration") == "iteration"]
        self.device = ""
        for b in self.rows:
            if " on " in b.get("label", ""):
                self.device = b["label"].rsplit(" on ", 1)[1]
                break
        self.commit = commits.get(name) or self.context.get("glint_commit") or commits.get("") or ""
        self.date = self.context.get("date", "")[:10]

    def caption(self):
        """'DEVICE, glint COMMIT, DATE' for a panel title."""
        parts = [self.device or "device not recorded", "glint " + (self.commit or "commit not recorded")]
        if self.date:
            parts.append(self.date)
        return ", ".join(parts)


def us_of(b):
    """Median GPU time of a benchmark row in microseconds (the median_us counter, else its time)."""
    if "median_us" in b:
        return b["median_us"]
    return b["real_time"] * TIME_TO_US[b.get("time_unit", "ns")]


def commit_map(values):
    """--commit values: NAME=COMMIT for one panel, a bare COMMIT (key '') for every panel."""
    out = {}
    for v in values or []:
        if "=" in v:
            k, c = v.split("=", 1)
            out[k] = c
        else:
            out[""] = v
    return out


def head_commit():
    return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()


def time_unit(times_us):
    """('ms', 1e-3) where the longest time is above 10 ms (CPU devices), else ('us', 1)."""
    return ("ms", 1e-3) if times_us and max(times_us) > 1e4 else ("us", 1.0)


def readable_log_axis(axis):
    """Label a log axis at 1, 2 and 5 times powers of ten, so that a span of less than a decade
    still has labelled ticks."""
    axis.set_major_locator(matplotlib.ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def spans_decades(values):
    return bool(values) and max(values) / min(values) > 20


def save(fig, args):
    fig.savefig(args.out)
    print("wrote", args.out)
    if args.png and not args.out.endswith(".png"):
        png = os.path.splitext(args.out)[0] + ".png"
        fig.savefig(png, dpi=110)
        print("wrote", png)


def runs_of(args):
    commits = commit_map(args.commit)
    return [Run(*spec.split("=", 1), commits) for spec in args.inputs]


def panels(n, width=6.2, height=4.8, legend_height=0.9, sharey=False):
    """Figure with n panels side by side (constrained layout) and a row below them for the legend:
    (fig, [axes], legend_axes). A legend outside the panels cannot hide a point."""
    fig = plt.figure(figsize=(width * n, height + legend_height), layout="constrained")
    grid = fig.add_gridspec(2, n, height_ratios=[height, legend_height])
    axes = []
    for i in range(n):
        axes.append(fig.add_subplot(grid[0, i], sharey=axes[0] if sharey and axes else None))
    legend_axes = fig.add_subplot(grid[1, :])
    legend_axes.axis("off")
    return fig, axes, legend_axes


def legend_below(legend_axes, handles, title, ncol, labels=None):
    kw = dict(loc="center", ncol=ncol, fontsize=8, title=title, title_fontsize=8, frameon=False)
    if labels is None:
        legend_axes.legend(handles=handles, **kw)
    else:
        legend_axes.legend(handles, labels, **kw)


# ---------------------------------------------------------------------------------------------
# Bloom

FILTERS = {0: "cod13", 1: "dual", 2: "gauss9"}
GUARDS = ["off", "karis", "karis_smooth"]


def bloom_points(run, size):
    """[(label, median_us, rel_l2)] for every BM_Bloom median at `size`, labels like
    'cod13, fp16, karis_smooth (defaults)'."""
    w, h = size.split("x")
    out = []
    for b in run.rows:
        if not b["name"].startswith("BM_Bloom/"):
            continue
        f = re.search(r"/fused:(\d)", b["name"])  # absent in files from before the fused dispatches
        if f and f.group(1) != "0":  # the default path
            continue
        m = re.search(r"w:(\d+)/h:(\d+)/filter:(\d)/fp32:(\d)", b["name"])
        if not m or (m.group(1), m.group(2)) != (w, h) or b.get("rel_l2_vs_f64", -1) < 0:
            continue
        g = re.search(r"guard:(\d)/l0h:(\d+)", b["name"])  # absent in files from before the guard
        parts = [FILTERS[int(m.group(3))], "fp32 levels" if m.group(4) == "1" else "fp16 levels"]
        parts.append(GUARDS[int(g.group(1))] if g else "karis")  # the per-box guard was the only one
        if g and g.group(2) != "0":
            parts.append("level0_height " + g.group(2))
        label = ", ".join(parts)
        if parts == ["cod13", "fp16 levels", "karis_smooth"]:
            label += " (defaults)"
        out.append((label, us_of(b), b["rel_l2_vs_f64"]))
    return out


def main_bloom(args):
    size = args.size or "1920x1080"
    runs = runs_of(args)
    data = [bloom_points(r, size) for r in runs]
    # One marker and colour per configuration, the same in every panel, named in one legend.
    labels = []
    for pts in data:
        for label, _, _ in pts:
            if label not in labels:
                labels.append(label)
    style = {label: (MARKERS[i % len(MARKERS)], f"C{i % 10}") for i, label in enumerate(labels)}
    fig, axes, legend_axes = panels(len(runs), height=4.4, legend_height=0.3 * (len(labels) + 2) / 3 + 0.3,
                                    sharey=True)
    for ax, run, pts in zip(axes, runs, data):
        unit, scale = time_unit([p[1] for p in pts])
        for label, us, err in pts:
            marker, colour = style[label]
            ax.scatter(us * scale, err, s=60, marker=marker, color=colour, edgecolors="black", linewidths=0.5,
                       zorder=3)
        if any(spans_decades([p[1] for p in d]) for d in data):  # the same scale in every panel
            ax.set_xscale("log")
            readable_log_axis(ax.xaxis)
        ax.margins(x=0.12, y=0.15)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(0, 0), useMathText=True)
        ax.set_xlabel(f"median GPU time per frame, {unit}")
        ax.set_title(f"bloom {size} on {run.name}\n{run.caption()}", fontsize=9)
        ax.grid(True, alpha=0.3)
        if not pts:
            ax.text(0.5, 0.5, f"no BM_Bloom runs at {size}", transform=ax.transAxes, ha="center")
    axes[0].set_ylabel("relative L2 error vs float64 reference")
    handles = [Line2D([], [], linestyle="", marker=style[l][0], color=style[l][1], markeredgecolor="black",
                      markeredgewidth=0.5, markersize=7, label=l) for l in labels]
    legend_below(legend_axes, handles, "configuration (filter, level precision, firefly guard)", min(3, len(handles)))
    save(fig, args)


# ---------------------------------------------------------------------------------------------
# Gaussian blur


def blur_points(run, size):
    """({method: [(median_us, rel_l2, sigma)]}, size) for every BM_Blur<Method> run with rel_l2 at
    `size` (default: the largest size in the file)."""
    found = []
    for b in run.rows:
        m = re.match(r"BM_Blur([A-Za-z0-9]+)/", b["name"])
        dims = re.search(r"w:(\d+)/h:(\d+)", b["name"])
        if m and "rel_l2" in b and dims:
            found.append((m.group(1), b, "x".join(dims.groups())))
    if size is None and found:
        size = max((f[2] for f in found), key=lambda s: int(s.split("x")[0]) * int(s.split("x")[1]))
    series = {}
    for method, b, dims in found:
        if dims != size:
            continue
        us, rel = us_of(b), b["rel_l2"]
        if not (rel > 0 and us > 0):  # log axes: a zero error would vanish; skip it loudly
            print(f"skipped {b['name']}: rel_l2 {rel}, time {us} us")
            continue
        series.setdefault(method, []).append((us, rel, b.get("sigma", float("nan"))))
    for pts in series.values():
        pts.sort(key=lambda p: p[2])
    return series, size


BLUR_NAMES = {"Separable": "separable", "SeparableLinear": "separable, linear taps", "Pyramid": "pyramid",
              "Dual": "dual", "Auto": "auto"}


def main_blur(args):
    runs = runs_of(args)
    data = [blur_points(r, args.size) for r in runs]
    methods = sorted({m for series, _ in data for m in series})
    style = {m: (MARKERS[i % len(MARKERS)], f"C{i}") for i, m in enumerate(methods)}
    sigmas = sorted({p[2] for series, _ in data for pts in series.values() for p in pts if p[2] == p[2]})
    norm = matplotlib.colors.LogNorm(vmin=min(sigmas or [1]), vmax=max(sigmas or [2]))
    cmap = matplotlib.colormaps["viridis"]
    fig, axes, legend_axes = panels(len(runs), height=5.0, legend_height=0.6, sharey=True)
    for ax, run, (series, size) in zip(axes, runs, data):
        times = [p[0] for pts in series.values() for p in pts]
        unit, scale = time_unit(times)
        for m in methods:
            pts = series.get(m, [])
            if not pts:
                continue
            marker, colour = style[m]
            # Line through the method's points in sigma order; markers filled by sigma.
            ax.plot([p[0] * scale for p in pts], [p[1] for p in pts], color=colour, alpha=0.6, lw=1.2, zorder=2)
            ax.scatter([p[0] * scale for p in pts], [p[1] for p in pts], marker=marker, s=55,
                       c=[cmap(norm(p[2])) for p in pts], edgecolors=colour, linewidths=1.5, zorder=3)
        ax.set_xscale("log")  # sigma 1.2 to 64 spans decades of time
        readable_log_axis(ax.xaxis)
        ax.set_yscale("log")
        ax.set_xlabel(f"median GPU time per frame, {unit} (log)")
        ax.set_title(f"Gaussian blur {size} on {run.name}\n{run.caption()}", fontsize=9)
        ax.grid(True, which="both", alpha=0.25)
        if not series:
            ax.text(0.5, 0.5, "no BM_Blur runs", transform=ax.transAxes, ha="center")
    axes[0].set_ylabel("relative L2 error vs exact Gaussian (log)")
    handles = [Line2D([], [], color=style[m][1], marker=style[m][0], markerfacecolor="white",
                      markeredgecolor=style[m][1], markeredgewidth=1.5, label=BLUR_NAMES.get(m, m)) for m in methods]
    legend_below(legend_axes, handles, "method (line through its sigmas; marker edge)", len(handles))
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=list(axes), pad=0.01, aspect=30)
    bar.set_label("sigma, px (marker fill)")
    bar.set_ticks(sigmas)
    bar.set_ticklabels([f"{s:g}" for s in sigmas])
    bar.minorticks_off()
    save(fig, args)


# ---------------------------------------------------------------------------------------------
# Lens-flare occlusion grid

PATTERNS = {None: "pattern not recorded", "0": "multi-jittered (default)", "1": "regular grid"}


def occlusion_points(run, lights):
    """({pattern: [(N, median_us, mean_abs_error)]}, lights) of BM_LightCull (automatic path, no
    per-light results, Hi-Z not timed) at `lights` (default: the most lights in the file)."""
    found = []
    for b in run.rows:
        m = re.match(r"BM_LightCull/n:(\d+)/grid:(\d+)/(?:path:0/)?results:0/hiz:0(?:/pattern:(\d))?/", b["name"])
        if m:
            found.append((int(m.group(1)), int(m.group(2)), m.group(3), b))
    if lights is None and found:
        lights = max(f[0] for f in found)
    out = {}
    for n, grid, pattern, b in found:
        if n == lights:
            out.setdefault(pattern, []).append((grid, us_of(b), b["mean_abs_error_vs_brute_force"]))
    for pts in out.values():
        pts.sort()
    return out, lights


# Label offsets (points) per grid size: alternate sides so that neighbours do not collide.
OCCLUSION_OFFSETS = {1: (8, 4), 4: (8, 4), 8: (8, 4), 16: (-10, 6)}


def main_occlusion(args):
    runs = runs_of(args)
    data = [occlusion_points(r, args.lights) for r in runs]
    fig, axes, legend_axes = panels(len(runs), height=4.8, legend_height=0.6, sharey=True)
    styles = {"0": ("-o", "C0"), None: ("-o", "C7"), "1": ("s", "C3")}
    used = []
    for ax, run, (series, lights) in zip(axes, runs, data):
        times = [p[1] for pts in series.values() for p in pts]
        unit, scale = time_unit(times)
        for pattern in ["0", None, "1"]:
            pts = series.get(pattern)
            if not pts:
                continue
            fmt, colour = styles[pattern]
            ax.plot([p[1] * scale for p in pts], [p[2] for p in pts], fmt, color=colour, ms=7, zorder=3,
                    mfc="white" if pattern == "1" else colour)
            if pattern not in used:
                used.append(pattern)
            if pattern == "1":
                for grid, us, err in pts:
                    ax.annotate(f"N={grid}", (us * scale, err), textcoords="offset points", xytext=(8, -12),
                                fontsize=8, color=colour)
                continue
            for grid, us, err in pts:
                ax.annotate(f"N={grid}", (us * scale, err), textcoords="offset points",
                            xytext=OCCLUSION_OFFSETS.get(grid, (8, 4)), fontsize=8,
                            ha="right" if OCCLUSION_OFFSETS.get(grid, (8, 4))[0] < 0 else "left")
        ax.set_xscale("log")
        ax.set_yscale("log")
        readable_log_axis(ax.xaxis)
        readable_log_axis(ax.yaxis)
        ax.margins(x=0.15, y=0.15)
        ax.set_xlabel(f"median GPU time of the cull, {unit} (log)")
        ax.set_title(f"occlusion grid N x N, {lights:,} lights, 1920x1080, on {run.name}\n{run.caption()}",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.25)
        if not series:
            ax.text(0.5, 0.5, "no BM_LightCull runs", transform=ax.transAxes, ha="center")
    axes[0].set_ylabel("mean |visible fraction - brute force| (log)")
    handles = [Line2D([], [], linestyle="-" if p != "1" else "", marker=styles[p][0][-1], color=styles[p][1],
                      markerfacecolor="white" if p == "1" else styles[p][1], label=PATTERNS[p]) for p in used]
    legend_below(legend_axes, handles, "sampling pattern (OcclusionPattern)", max(1, len(handles)))
    save(fig, args)


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
    commits = commit_map(args.commit)
    peers = dict(spec.split("=", 1) for spec in (args.peer or []))
    fig, axes = plt.subplots(1, len(args.inputs), figsize=(6.0 * len(args.inputs), 4.8), squeeze=False)
    captions = []
    markers = "osD^vP*X"
    for ax, spec in zip(axes[0], args.inputs):
        name, path = spec.split("=", 1)
        pts, device = object_cull_points(path, args.objects)
        commit = commits.get(name) or json.load(open(path)).get("context", {}).get("glint_commit") or \
            commits.get("") or head_commit()
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
        captions.append(f"{name}: {device or 'device unknown'}, glint {commit}")
    fig.text(0.01, 0.01, "; ".join(captions), fontsize=7, ha="left", va="bottom")
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    save(fig, args)


# ---------------------------------------------------------------------------------------------
# Firefly stability (build/bench/glint_stability_report's data)

GUARD_STYLE = {"karis_smooth": "-", "karis": "--", "off": ":"}
FILTER_COLOUR = {"cod13": "C0", "dual": "C1", "gauss9": "C2"}


def brightness(v):
    """1e4 rather than 10000."""
    e = math.floor(math.log10(v))
    return f"{v / 10 ** e:g}e{e}" if v >= 1000 else f"{v:g}"


class FireflyRun:
    """One glint_stability_report directory: its firefly_energy.json, the folder its raw filmstrip
    lies in, the panel's name (DEVICE of DEVICE=DIR, else the JSON's device) and the commit."""

    def __init__(self, spec, commits):
        # DEVICE=DIR, or a bare DIR (also one whose name holds '=': it is a directory).
        name, folder = (None, spec) if os.path.isdir(spec) or "=" not in spec else spec.split("=", 1)
        path = os.path.join(folder, "firefly_energy.json")
        if not os.path.isfile(path):
            raise SystemExit(f"--chart firefly: {path} does not exist (write it with "
                             f"build/bench/glint_stability_report --out {folder})")
        self.data = json.load(open(path))
        self.folder = folder
        self.device = self.data.get("device", "")
        self.name = name or self.device or folder
        self.commit = commits.get(self.name) or commits.get("")
        self.series = [s for s in self.data["series"] if s["max_brightness"] == 1000 and s["value"] == 1e4]
        if not self.series:
            raise SystemExit(f"{path} has no max_brightness 1000, value 1e4 series")

    def caption(self):
        """'NAME: DEVICE, glint COMMIT' (the name once where it is the device)."""
        who = self.device if self.name == self.device else f"{self.name}: {self.device or 'device not recorded'}"
        return f"{who}, glint {self.commit}"


def firefly_label(s):
    label = s["filter"] + ", " + s["firefly_guard"]
    if s["filter"] == "cod13" and s["firefly_guard"] == "karis_smooth":
        label += " (defaults)"
    return label


def relative_energy(s):
    e = s["energy"]
    mean = sum(e) / len(e)
    return [v / mean for v in e]


def firefly_panel(ax, run, zoom):
    """One device's energy lines: every configuration, or (zoom) those that stay inside +-3%."""
    data = run.data
    for s in run.series:
        rel = relative_energy(s)
        if zoom and max(abs(v - 1.0) for v in rel) > 0.03:
            continue  # the zoom shows the lines that stay inside it
        ax.plot(range(len(rel)), rel, GUARD_STYLE.get(s["firefly_guard"], "-"),
                color=FILTER_COLOUR.get(s["filter"], "C7"), lw=1.4, label=firefly_label(s))
    for v in (0.98, 1.02):
        ax.axhline(v, color="grey", lw=0.8, alpha=0.7)
    ax.set_xlabel(f"frame (point at x = {data['x0_px']:g} + {data['step_px']:g} x frame px)")
    ax.set_xlim(0, len(run.series[0]["energy"]) - 1)
    ax.grid(True, alpha=0.3)
    if zoom:
        ax.set_ylim(0.97, 1.03)


def firefly_energy_chart(runs, out):
    """firefly_energy.png: one device, the whole range and the zoom side by side; several devices,
    one column per device (top: all configurations, bottom: the zoom). One legend below for all
    panels, each line's spread per device in its label."""
    n = len(runs)
    labels, spreads = [], {}
    for run in runs:
        for s in run.series:
            rel = relative_energy(s)
            label = firefly_label(s)
            if label not in labels:
                labels.append(label)
            spreads.setdefault(label, []).append((run.name, (max(rel) - min(rel)) * 100.0))

    def with_spread(label):
        if n == 1:
            return f"{label}: spread {spreads[label][0][1]:.2g}%"
        return f"{label}: spread " + ", ".join(f"{v:.2g}% {name}" for name, v in spreads[label])

    legend_labels = [with_spread(l) for l in labels]
    # Up to 3 legend columns, fewer where long labels (long device names) would not fit the
    # figure's width: about 0.05 in per character at 8 pt, plus the line sample and the gap.
    column_in = 0.05 * max(len(l) for l in legend_labels) + 0.6
    ncol = max(1, min(3, int(6.4 * max(n, 2) // column_in)))
    legend_height = 0.3 * math.ceil(len(labels) / ncol) + 0.4
    if n == 1:
        fig = plt.figure(figsize=(12.8, 4.6 + legend_height), layout="constrained")
        grid = fig.add_gridspec(2, 2, height_ratios=[4.6, legend_height])
        full, zoom = [fig.add_subplot(grid[0, 0])], [fig.add_subplot(grid[0, 1])]
        legend_axes = fig.add_subplot(grid[1, :])
    else:
        fig = plt.figure(figsize=(6.4 * n, 8.4 + legend_height), layout="constrained")
        grid = fig.add_gridspec(3, n, height_ratios=[4.2, 4.2, legend_height])
        full, zoom = [], []
        for i in range(n):
            full.append(fig.add_subplot(grid[0, i], sharey=full[0] if full else None))
            zoom.append(fig.add_subplot(grid[1, i], sharey=zoom[0] if zoom else None))
        legend_axes = fig.add_subplot(grid[2, :])
    legend_axes.axis("off")
    for run, a, z in zip(runs, full, zoom):
        firefly_panel(a, run, False)
        firefly_panel(z, run, True)
        where = "" if n == 1 else f"{run.caption()}\n"
        a.set_title(f"{where}all configurations (grey: +-2%)", fontsize=9)
        z.set_title(f"{where}zoom on +-3%: the lines that stay inside it (grey: the 2% target)", fontsize=9)
    full[0].set_ylabel("bloom energy / its mean over the 64 frames")
    zoom[0].set_ylabel("bloom energy / its mean over the 64 frames (zoom)")
    # One handle per configuration (the same colour and style in every panel).
    handles = {}
    for ax in full:
        for h, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, h)

    legend_below(legend_axes, [handles[l] for l in labels],
                 "filter, firefly_guard (max_brightness 1000); spread = (max - min) / mean", ncol, legend_labels)
    w, h = runs[0].data["image"]
    title = f"Moving firefly of {brightness(runs[0].series[0]['value'])} on a {w}x{h} image, bloom energy per frame"
    fig.suptitle(title + (f"\n{runs[0].caption()}" if n == 1 else ""), fontsize=10)
    fig.savefig(out, dpi=110)
    print("wrote", out)


def firefly_frames_chart(runs, out):
    """firefly_frames.png: each device's raw filmstrip (firefly_frames_raw.png, one row per guard,
    one column per frame), one block per device stacked vertically and labelled with it."""
    n = len(runs)
    strips = [r.data["filmstrip"] for r in runs]
    frames = max(s["frames"] for s in strips)
    heights = [1.75 * len(s["rows"]) + (0.45 if n > 1 else 0.0) for s in strips]
    fig = plt.figure(figsize=(2.9 * frames, sum(heights) + 0.9), layout="constrained")
    blocks = [fig] if n == 1 else fig.subfigures(n, 1, height_ratios=heights)
    for block, run, strip in zip(blocks, runs, strips):
        data = run.data
        raw = plt.imread(os.path.join(run.folder, strip["file"]))
        tw, th = strip["tile"]
        rows = strip["rows"]
        axes = block.subplots(len(rows), frames, squeeze=False)
        for r, guard in enumerate(rows):
            for f in range(frames):
                ax = axes[r][f]
                ax.set_xticks([])
                ax.set_yticks([])
                if f >= strip["frames"]:
                    ax.axis("off")
                    continue
                ax.imshow(raw[r * th:(r + 1) * th, f * tw:(f + 1) * tw], interpolation="nearest")
                ax.set_title(f"frame {f}, x = {data['x0_px'] + data['step_px'] * f:g} px", fontsize=8)
                if f == 0:
                    name = guard + (" (default)" if guard == "karis_smooth" else "")
                    ax.set_ylabel(f"cod13\n{name}", fontsize=8)
        if n > 1:
            block.suptitle(run.caption(), fontsize=9, fontweight="bold")
    s = strips[0]
    tw, th = s["tile"]
    title = (f"Frames of the moving {brightness(s['value'])} point ({tw}x{th} crops around it), intensity "
             f"{s['intensity']:g}, exposure {s['exposure']:g}")
    if n == 1:
        fig.suptitle(f"{title}\n{runs[0].caption()}", fontsize=9)
    else:
        fig.suptitle(title, fontsize=10)
    fig.savefig(out, dpi=110)
    print("wrote", out)


def main_firefly(args):
    commits = commit_map(args.commit)
    runs = [FireflyRun(spec, commits) for spec in args.inputs]
    names = [r.name for r in runs]
    if len(set(names)) != len(names):
        raise SystemExit(f"--chart firefly: two inputs are named alike ({', '.join(names)}): use DEVICE=DIR")
    for key in commits:
        if key and key not in names:
            raise SystemExit(f"--commit {key}=...: no input is named {key} (inputs: {', '.join(names)})")
    if args.out and args.out_dir:
        raise SystemExit("--chart firefly: give --out (the energy chart's file) or --out-dir, not both")
    for run in runs:
        if not run.commit:  # the report's JSON does not record the commit: take HEAD, and say so
            head = head_commit()
            run.commit = head or "commit not recorded"
            print(f"{run.name}: no --commit: " + (f"captioned with HEAD ({head})" if head else "no git HEAD either"))
    if args.out:
        out_dir = os.path.dirname(args.out) or "."
    else:
        out_dir = args.out_dir or (runs[0].folder if len(runs) == 1 else "docs/stability")
    os.makedirs(out_dir, exist_ok=True)
    firefly_energy_chart(runs, args.out or os.path.join(out_dir, "firefly_energy.png"))
    firefly_frames_chart(runs, os.path.join(out_dir, "firefly_frames.png"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inputs", nargs="+",
                    help="DEVICE=results.json (--chart firefly: DEVICE=DIR or DIR, the report's directory)")
    ap.add_argument("--chart", choices=["bloom", "blur", "occlusion", "object_cull", "firefly"], default="bloom")
    ap.add_argument("--size", default=None, help="WxH (bloom default 1920x1080; blur default: each file's largest)")
    ap.add_argument("--out", default=None, help="default docs/charts/<chart>_pareto.svg "
                                                "(--chart firefly: the energy chart's PNG; frames go beside it)")
    ap.add_argument("--out-dir", default=None,
                    help="--chart firefly: folder of firefly_energy.png and firefly_frames.png (default: the "
                         "input's folder for one input, docs/stability for several)")
    ap.add_argument("--lights", type=int, default=None, help="occlusion chart: light count (default: each file's most)")
    ap.add_argument("--objects", type=int, default=1000000, help="object count of the object_cull chart")
    ap.add_argument("--peer", action="append", help="DEVICE=object_cull_torch.json (object_cull chart)")
    ap.add_argument("--commit", action="append",
                    help="NAME=COMMIT: glint commit of panel NAME where its JSON does not record one; "
                         "a bare COMMIT applies to every panel (firefly default: git rev-parse --short HEAD)")
    ap.add_argument("--png", action="store_true", help="also write a PNG next to the SVG")
    args = ap.parse_args()
    if args.out_dir and args.chart != "firefly":
        ap.error("--out-dir is for --chart firefly (the other charts take --out FILE)")
    if args.out is None and args.chart != "firefly":
        args.out = "docs/charts/object_cull_fp_time.svg" if args.chart == "object_cull" else \
            f"docs/charts/{args.chart}_pareto.svg"
    return {"bloom": main_bloom, "blur": main_blur, "occlusion": main_occlusion, "object_cull": main_object_cull,
            "firefly": main_firefly}[args.chart](args)


if __name__ == "__main__":
    main()
