#!/usr/bin/env python3
r"""The speed table of docs/PERF.md, from glint_bench JSON runs and the peers' JSON of the same calls.

Each row is one job of the speed targets: glint's median GPU time, the time of a copy of the same
image measured in the same run (BM_CopyFloor; a blank where the job has no image of that size),
glint / copy, the best peer's median and peer / glint, the glint commit and the target (the H100's;
with --cpu the cell says so and "met" stays blank). Times of 10 ms or more print in ms. Medians come from
--benchmark_repetitions aggregates when present, single runs otherwise.

    python3 bench/perf_table.py --commit abc1234 --glint h100.json \
        --peer bloom=bloom_torch.json --peer blur=blur_torch.json --peer occlusion=occlusion_torch.json \
        --peer object_cull=object_cull_torch.json

Peer files are those bench/peers/*.py write; a missing peer leaves its column blank. --glint may be
given once per glint_bench run (a device call's time limit can split the rows over several runs):
a row takes its time, its copy and its commit (the run's glint_commit context, unless --commit
names one for all) from the first run that holds it. --not-h100 marks a GPU other
than the H100 the targets were set on (the target cell names the H100, "met" stays blank).

CPU devices (lavapipe) take some rows at a smaller size (CPU_SIZES: a row whose run would take
minutes per repetition there); --cpu selects that row set, and the label names the size run.
--filter prints the --benchmark_filter for the rows and their copies, nothing else:

    glint_bench --benchmark_filter="$(python3 bench/perf_table.py --filter --cpu)" ...
    python3 bench/perf_table.py --cpu --commit abc1234 --glint lavapipe.json

A row whose benchmark is not in the run is listed under the table, with the benchmark's error
where it reported one (e.g. a buffer above the device's maxStorageBufferRange).
"""
import argparse
import json
import re

# (label, glint benchmark name without /manual_time, copy-floor size or None, peer key, target us)
ROWS = [
    ("bloom 1920x1080, defaults (karis_smooth)", "BM_Bloom/w:1920/h:1080/filter:0/fp32:0/guard:2/l0h:0/fused:0",
     "1920x1080", "bloom:1920x1080", 60),
    ("bloom 1920x1080, per-box Karis guard", "BM_Bloom/w:1920/h:1080/filter:0/fp32:0/guard:1/l0h:0/fused:0",
     "1920x1080", "bloom:1920x1080", None),
    ("bloom 3840x2160, defaults (karis_smooth)", "BM_Bloom/w:3840/h:2160/filter:0/fp32:0/guard:2/l0h:0/fused:0",
     "3840x2160", "bloom:3840x2160", 150),
    ("separable blur sigma 1.2 (11 taps), 3840x2160", "BM_BlurSeparable/sigma10:12/w:3840/h:2160", "3840x2160",
     "blur:9tap", 60),
    ("3-level BlurPyramid 3840x2160", "BM_PyramidLevels3/w:3840/h:2160", "3840x2160", None, 50),
    ("Gaussian sigma 16, 3840x2160, auto", "BM_BlurAuto/sigma10:160/w:3840/h:2160", "3840x2160", None, 100),
    ("Gaussian sigma 64, 3840x2160, auto", "BM_BlurAuto/sigma10:640/w:3840/h:2160", "3840x2160", None, 100),
    ("Gaussian sigma 4, 3840x2160, separable", "BM_BlurSeparable/sigma10:40/w:3840/h:2160", "3840x2160", None,
     120),
    ("Gaussian sigma 4, 3840x2160, pyramid", "BM_BlurPyramid/sigma10:40/w:3840/h:2160", "3840x2160", None, 120),
    ("Gaussian sigma 4, 3840x2160, auto", "BM_BlurAuto/sigma10:40/w:3840/h:2160", "3840x2160", None, 120),
    ("Hi-Z 3840x2160 D32, all levels", "BM_HiZBuild/w:3840/h:2160", None, "hiz:3840x2160", 20),
    ("cull + 4x4 occlusion + ordered compaction, 1 M lights", "BM_LightCull/n:1000000/grid:4/results:0/hiz:0/pattern:0",
     None, "compaction:1000000", 60),
    ("10 lights end to end 1080p, compute", "BM_FlareEndToEnd/lights:10/compute:1/visibility:0", None, None, 30),
    ("10 lights end to end 1080p, raster", "BM_FlareEndToEnd/lights:10/compute:0/visibility:0", None, None, 30),
    ("flare draw, 1000 lights 1080p, compute", "BM_FlareDraw/w:1920/h:1080/lights:1000/compute:1/sizes:0", None,
     None, 200),
    ("flare draw, 1000 lights 1080p, raster", "BM_FlareDraw/w:1920/h:1080/lights:1000/compute:0/sizes:0", None,
     None, 200),
    ("object cull, 1 M objects", "BM_ObjectCull/objects:1000000", None, "object_cull:1000000", 40),
    ("object cull, 10 M objects", "BM_ObjectCull/objects:10000000", None, "object_cull:10000000", None),
]

# --cpu: benchmark of a row -> the size run instead on CPU devices. The separable blur that `auto`
# resolves to at sigma 64 (2 x 513 taps) took 2.4 s per 960x540 frame on lavapipe (2 cores), so
# about 40 s per 3840x2160 frame and 6 minutes for the 9 frames of 3 repetitions; 960x540 is the
# size bench/blur_bench.cpp registers for CPU devices.
CPU_SIZES = {
    "BM_BlurAuto/sigma10:640/w:3840/h:2160": "960x540",
}
# Sizes BM_CopyFloor is registered at (bench/copy_bench.cpp).
COPY_SIZES = ("640x480", "1920x1080", "3840x2160", "7680x4320")


def sized_rows(cpu):
    """ROWS with CPU_SIZES applied when cpu: the benchmark name, label and copy size say the size run."""
    out = []
    for label, name, floor, peer, target in ROWS:
        size = CPU_SIZES.get(name) if cpu else None
        if size:
            w, h = size.split("x")
            old = re.search(r"w:(\d+)/h:(\d+)", name).groups()
            name = re.sub(r"w:\d+/h:\d+", f"w:{w}/h:{h}", name)
            label = label.replace("x".join(old), f"{size} (GPU row: {'x'.join(old)})")
            floor = size if floor else None
        out.append((label, name, floor, peer, target))
    return out


def benchmark_filter(rows):
    """A --benchmark_filter regex matching exactly the rows' benchmarks and their copies."""
    names = [name for _, name, _, _, _ in rows]
    names += sorted({f"BM_CopyFloor/w:{f.split('x')[0]}/h:{f.split('x')[1]}" for _, _, f, _, _ in rows
                     if f and f in COPY_SIZES})
    return "|".join("^" + re.escape(n).replace("\\/", "/") + "/" for n in names)


def glint_medians(path):
    """name (no /manual_time, no aggregate suffix) -> median time in us, the context, and
    name -> error message of the benchmarks that reported one."""
    data = json.load(open(path))
    out, single, errors = {}, {}, {}
    for b in data["benchmarks"]:
        name = re.sub(r"/manual_time.*$", "", b["run_name"] if "run_name" in b else b["name"])
        if b.get("error_occurred"):
            errors[name] = b.get("error_message", "error")
            continue
        scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[b.get("time_unit", "ns")]
        # The median frame (the counter median_us; for the median aggregate, the median of the
        # repetitions' medians). The manual time is each repetition's mean over its iterations,
        # which one slow iteration moves (the sigma-64 blur: 5630 against 4800 us on the H100).
        t = b.get("median_us", b["real_time"] * scale)
        if b.get("aggregate_name") == "median":
            out[name] = t
        elif "aggregate_name" not in b:
            single.setdefault(name, t)
    for k, v in single.items():
        out.setdefault(k, v)
    return out, data.get("context", {}), errors


def peer_medians(specs):
    """'kind=path' arguments -> {key: (median_us, peer name)} for the keys ROWS use."""
    out = {}
    for spec in specs:
        kind, path = spec.split("=", 1)
        d = json.load(open(path))
        if kind == "bloom":
            for r in d["bloom"]:
                out[f"bloom:{r['width']}x{r['height']}"] = (r["median_us"], "PyTorch chain, CUDA graph")
        elif kind == "blur":
            best = min((r for r in d["results"] if r["peer"] not in ("torch_copy", "torch_clone")),
                       key=lambda r: r["median_us"])
            out["blur:9tap"] = (best["median_us"], best["peer"])
        elif kind == "occlusion":
            for r in d.get("hiz", []):
                out[f"hiz:{r['width']}x{r['height']}"] = (r["median_us"], "max_pool pyramid, CUDA graph")
            if "compaction" in d:
                c = d["compaction"]
                out[f"compaction:{c['lights']}"] = (c["median_us"], "nonzero + gather alone")
        elif kind == "object_cull":
            for r in d["object_cull"]:  # the fastest of the peer's methods
                key = f"object_cull:{r['objects']}"
                if key not in out or r["median_us"] < out[key][0]:
                    out[key] = (r["median_us"], r.get("peer", "PyTorch"))
        else:
            raise SystemExit(f"unknown peer kind {kind!r}; accepted: bloom, blur, occlusion, object_cull")
    return out


def fmt_us(t):
    """A time in us as the table prints it: us below 10 ms, ms above (CPU devices)."""
    return f"{t:.1f} us" if t < 1e4 else f"{t / 1e3:.1f} ms"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", action="append", default=[],
                    help="glint_bench JSON; several runs may be given (each row's copy comes from its own run)")
    ap.add_argument("--peer", action="append", default=[], help="KIND=FILE, KIND one of bloom, blur, occlusion, "
                    "object_cull")
    ap.add_argument("--commit", help="the glint commit of every row (default: each run's glint_commit context)")
    ap.add_argument("--cpu", action="store_true", help="the CPU-device row set (CPU_SIZES)")
    ap.add_argument("--not-h100", action="store_true",
                    help="a GPU other than the H100 the targets were set on: the target cell names the H100 and "
                    "\"met\" stays blank")
    ap.add_argument("--filter", action="store_true", help="print the rows' --benchmark_filter and exit")
    args = ap.parse_args()
    rows = sized_rows(args.cpu)
    if args.filter:
        print(benchmark_filter(rows))
        return
    if not args.glint:
        ap.error("--glint is required (or --filter)")
    # Each run's medians, in order; a row takes its time, its copy and its commit from the first run that
    # holds it.
    runs = [glint_medians(path) for path in args.glint]
    errors = {k: v for r in runs for k, v in r[2].items()}
    g, run_of = {}, {}
    for i, (medians, _, _) in enumerate(runs):
        for k, v in medians.items():
            if k not in g:
                g[k], run_of[k] = v, i
    peers = peer_medians(args.peer)

    def commit_of(i):
        """The commit a row of run i names: --commit, else the run's glint_commit context."""
        c = args.commit or runs[i][1].get("glint_commit")
        if not c:
            raise SystemExit(f"{args.glint[i]} names no glint_commit in its context: give --commit")
        return c

    for i in sorted(set(run_of.values())):
        commit_of(i)  # every run a row comes from names its commit, before anything is printed
    print("| job | glint median | copy of the same image | glint / copy | best peer | peer / glint | commit | target "
          "| met |")
    print("| --- | ---: | ---: | ---: | --- | ---: | --- | ---: | --- |")
    missing = []
    for label, name, floor, peer, target in rows:
        if name not in g:
            missing.append((label, name))
            continue
        t = g[name]
        copy = f"BM_CopyFloor/w:{floor.split('x')[0]}/h:{floor.split('x')[1]}" if floor else None
        f = runs[run_of[name]][0].get(copy) if copy else None
        p = peers.get(peer) if peer else None
        # Targets are the H100's: on another device the cell says so and "met" stays blank.
        other = args.cpu or args.not_h100
        tcell = (f"{target} us on an H100" if other else f"{target} us") if target else ""
        met = ("yes" if t <= target else "no") if target and not other else ""
        cells = [label, fmt_us(t), fmt_us(f) if f else "", f"{t / f:.1f}x" if f else "",
                 f"{p[1]}: {p[0]:.0f} us" if p else "", f"{p[0] / t:.1f}x" if p else "", commit_of(run_of[name]),
                 tcell, met]
        print("| " + " | ".join(cells) + " |")
    for i, (path, (_, c, _)) in enumerate(zip(args.glint, runs)):
        print(f"\n{path}: glint at {commit_of(i)}; {c.get('date', '')}", end="")
    print()
    for label, name, floor, _, _ in rows:
        if name in g and floor and floor not in COPY_SIZES:
            print(f"- {label}: no BM_CopyFloor at {floor} (registered: {', '.join(COPY_SIZES)})")
    for label, name in missing:
        why = f"error: {errors[name]}" if name in errors else "not in this run"
        print(f"- {label} (`{name}`): {why}")


if __name__ == "__main__":
    main()
