#!/usr/bin/env python3
"""The speed table of docs/PERF.md, from one glint_bench JSON and the peers' JSON of the same run.

Each row is one job of the speed targets: glint's median GPU time, the time of a copy of the same
image measured in the same run (BM_CopyFloor; a blank where the job has no image of that size),
glint / copy, the best peer's median and peer / glint, and the target. Medians come from
--benchmark_repetitions aggregates when present, single runs otherwise.

    python3 bench/perf_table.py --commit abc1234 --glint h100.json \
        --peer bloom=bloom_torch.json --peer blur=blur_torch.json --peer occlusion=occlusion_torch.json \
        --peer object_cull=object_cull_torch.json

Peer files are those bench/peers/*.py write; a missing peer leaves its column blank.
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
    ("9-tap separable blur 3840x2160", "BM_BlurSeparable/sigma10:12/w:3840/h:2160", "3840x2160", "blur:9tap", 60),
    ("3-level BlurPyramid 3840x2160", "BM_PyramidLevels3/w:3840/h:2160", "3840x2160", None, 50),
    ("Gaussian sigma 16, 3840x2160, auto", "BM_BlurAuto/sigma10:160/w:3840/h:2160", "3840x2160", None, 100),
    ("Gaussian sigma 64, 3840x2160, auto", "BM_BlurAuto/sigma10:640/w:3840/h:2160", "3840x2160", None, 100),
    ("Gaussian sigma 4, 3840x2160, separable", "BM_BlurSeparable/sigma10:40/w:3840/h:2160", "3840x2160", None,
     120),
    ("Gaussian sigma 4, 3840x2160, pyramid", "BM_BlurPyramid/sigma10:40/w:3840/h:2160", "3840x2160", None, 120),
    ("Gaussian sigma 4, 3840x2160, auto", "BM_BlurAuto/sigma10:40/w:3840/h:2160", "3840x2160", None, 120),
    ("Hi-Z 3840x2160 D32, all levels", "BM_HiZBuild/w:3840/h:2160", None, "hiz:3840x2160", 20),
    ("cull + 4x4 occlusion + ordered compaction, 1 M lights", "BM_LightCull/n:1000000/grid:4/results:0/hiz:0",
     None, "compaction:1000000", 60),
    ("10 lights end to end 1080p, compute", "BM_FlareEndToEnd/lights:10/compute:1", None, None, 30),
    ("10 lights end to end 1080p, raster", "BM_FlareEndToEnd/lights:10/compute:0", None, None, 30),
    ("flare draw, 1000 lights 1080p, compute", "BM_FlareDraw/w:1920/h:1080/lights:1000/compute:1/sizes:0", None,
     None, 200),
    ("flare draw, 1000 lights 1080p, raster", "BM_FlareDraw/w:1920/h:1080/lights:1000/compute:0/sizes:0", None,
     None, 200),
    ("object cull, 1 M objects", "BM_ObjectCull/objects:1000000", None, "object_cull:1000000", 40),
    ("object cull, 10 M objects", "BM_ObjectCull/objects:10000000", None, "object_cull:10000000", None),
]


def glint_medians(path):
    """name (no /manual_time, no aggregate suffix) -> median time in us, and the context."""
    data = json.load(open(path))
    out, single = {}, {}
    for b in data["benchmarks"]:
        name = re.sub(r"/manual_time.*$", "", b["run_name"] if "run_name" in b else b["name"])
        scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[b.get("time_unit", "ns")]
        t = b.get("median_us", b["real_time"] * scale) if b.get("aggregate_name") != "median" else \
            b["real_time"] * scale
        if b.get("aggregate_name") == "median":
            out[name] = t
        elif "aggregate_name" not in b:
            single.setdefault(name, t)
    for k, v in single.items():
        out.setdefault(k, v)
    return out, data.get("context", {})


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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", required=True, help="glint_bench JSON")
    ap.add_argument("--peer", action="append", default=[], help="KIND=FILE, KIND one of bloom, blur, occlusion, "
                    "object_cull")
    ap.add_argument("--commit", required=True)
    args = ap.parse_args()
    g, ctx = glint_medians(args.glint)
    peers = peer_medians(args.peer)
    print("| job | glint median | copy of the same image | glint / copy | best peer | peer / glint | target | met |")
    print("| --- | ---: | ---: | ---: | --- | ---: | ---: | --- |")
    for label, name, floor, peer, target in ROWS:
        if name not in g:
            continue
        t = g[name]
        f = g.get(f"BM_CopyFloor/w:{floor.split('x')[0]}/h:{floor.split('x')[1]}") if floor else None
        p = peers.get(peer) if peer else None
        cells = [label, f"{t:.1f} us", f"{f:.1f} us" if f else "", f"{t / f:.1f}x" if f else "",
                 f"{p[1]}: {p[0]:.0f} us" if p else "", f"{p[0] / t:.1f}x" if p else "",
                 f"{target} us" if target else "", ("yes" if t <= target else "no") if target else ""]
        print("| " + " | ".join(cells) + " |")
    print(f"\nglint at {args.commit}; {ctx.get('date', '')}")


if __name__ == "__main__":
    main()
