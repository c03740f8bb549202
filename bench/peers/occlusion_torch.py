"""PyTorch/CUDA peer baselines for glint's flare visibility benchmarks (bench/occlusion_bench.cpp).

What it measures, on the same machine and in the same session as glint:
  1. Hi-Z pyramid: a D32-like float32 depth buffer (1, 1, H, W) reduced level by level with
     F.max_pool2d(kernel 2, stride 2, ceil_mode=True) until 1x1 (ceil mode keeps the odd
     row/column, so no texel is lost, like glint's fold rule). Captured once in a CUDA graph and
     replayed; each replay timed with CUDA events (median of --reps). docs/PERF.md has the
     measured peer (60.7 us for 3840x2160 on an H100).
  2. Compaction of 1,000,000 lights: given a visibility mask (about half visible) and the light
     records (12 float32 each, 48 bytes like GlintFlareLight), torch.nonzero + index_select, the
     stream-compaction part of glint's cull alone (no projection, no occlusion test). nonzero
     synchronises with the host, so it cannot be graph-captured; it is timed with CUDA events
     around each call (docs/PERF.md: 361 us on an H100).

Usage: python3 bench/peers/occlusion_torch.py [--sizes 3840x2160,1920x1080] [--lights 1000000]
                                              [--reps 200] [--out occlusion_torch.json]
Exits with status 0 and a message when PyTorch or CUDA is not available.
"""
import argparse
import json
import sys

try:
    import torch
    import torch.nn.functional as F
except ImportError:  # the guard the lead asked for: no torch, no failure
    print("occlusion_torch.py: PyTorch is not installed; no peer numbers", file=sys.stderr)
    sys.exit(0)

from peer_timing import timed_eager, timed_graph  # noqa: E402 (after the torch guard)


def hiz_pyramid(depth):
    levels = []
    x = depth
    while x.shape[-1] > 1 or x.shape[-2] > 1:
        x = F.max_pool2d(x, kernel_size=2, stride=2, ceil_mode=True)
        levels.append(x)
    return levels


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="3840x2160,1920x1080")
    ap.add_argument("--lights", type=int, default=1_000_000)
    ap.add_argument("--reps", type=int, default=200)
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    if not torch.cuda.is_available():
        print("occlusion_torch.py: CUDA is not available to PyTorch; no peer numbers", file=sys.stderr)
        return 0
    dev = torch.device("cuda")
    results = {"device": torch.cuda.get_device_name(0), "torch": torch.__version__, "hiz": [], "compaction": {}}
    for size in args.sizes.split(","):
        w, h = (int(v) for v in size.split("x"))
        depth = torch.rand((1, 1, h, w), device=dev, dtype=torch.float32)
        ms = timed_graph(lambda: hiz_pyramid(depth), args.reps)
        results["hiz"].append({"width": w, "height": h, "median_us": ms * 1e3})
        print(f"hi-z max_pool2d pyramid {w}x{h}: {ms * 1e3:.1f} us (CUDA graph)")

    n = args.lights
    lights = torch.rand((n, 12), device=dev, dtype=torch.float32)
    visible = torch.rand(n, device=dev) < 0.5

    def compact():
        idx = torch.nonzero(visible, as_tuple=False).squeeze(1)
        return lights.index_select(0, idx)

    ms = timed_eager(compact, args.reps)
    results["compaction"] = {"lights": n, "median_us": ms * 1e3}
    print(f"compaction of {n} lights (nonzero + index_select): {ms * 1e3:.1f} us")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=2)
        print("wrote", args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
