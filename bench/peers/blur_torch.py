"""PyTorch and CuPy peer baselines for glint's Gaussian blur benchmark (bench/blur_bench.cpp).

What it measures, on the same machine and in the same session as glint:
  1. Device-to-device copy bandwidth (PyTorch): a 1 GiB `dst.copy_(src)`, median of >= 20 timed
     copies, in TB/s counting bytes read + bytes written, as bench/peers/bloom_torch.py does.
     Plus a `clone()` of the RGBA16F image itself, the smallest same-size "filter" there is.
  2. torch_conv2d: the 9-tap Gaussian (sigma 1.2, taps 2 ceil(3 sigma) + 1 as docs/BLUR.md) as a
     pair of depthwise conv2d, horizontal (1x9) then vertical (9x1), groups = 4 channels, fp16
     NCHW 1x4xHxW, replicate padding (clamp-to-edge, as glint). Captured in a CUDA graph.
  3. cupy_gaussian_filter: cupyx.scipy.ndimage.gaussian_filter on float32 HxWx4 with sigma 1.2 and
     truncate = 4 / 1.2 (radius 4: the same 9 taps), axes y and x only, mode 'nearest'.
Each is timed with CUDA events around every run (warm-up first) and reported as the median.
Each peer is independent: a missing torch, cupy or CUDA skips that peer with a message (exit 0).

Output: one JSON object per line on stdout (like the lines bloom_torch.py writes to its JSON
file), and all of them in --out.

Usage: python3 bench/peers/blur_torch.py [--size 3840x2160] [--sigma 1.2] [--reps 200]
                                         [--out blur_torch.json]
"""
import argparse
import json
import math
import statistics
import sys

C = 4  # RGBA


def gaussian_taps(sigma):
    """Normalized taps w[-R..R], R = max(1, ceil(3 sigma)) (docs/BLUR.md)."""
    r = max(1, math.ceil(3.0 * sigma))
    w = [math.exp(-t * t / (2.0 * sigma * sigma)) for t in range(-r, r + 1)]
    s = sum(w)
    return [v / s for v in w]


def emit(record, results):
    results.append(record)
    print(json.dumps(record), flush=True)


def median_us(run, reps, warmup, event_factory, synchronize):
    """Median of `reps` timings of run() in microseconds, each between two CUDA events."""
    for _ in range(warmup):
        run()
    synchronize()
    events = [(event_factory(), event_factory()) for _ in range(reps)]
    for a, b in events:
        a.record()
        run()
        b.record()
    synchronize()
    def elapsed_ms(a, b):
        if hasattr(a, "elapsed_time"):  # torch.cuda.Event
            return a.elapsed_time(b)
        import cupy  # cupy.cuda.Event has no method; the module function times a pair

        return cupy.cuda.get_elapsed_time(a, b)

    return statistics.median([elapsed_ms(a, b) * 1e3 for a, b in events])  # ms -> us


def torch_peers(width, height, sigma, reps, results):
    try:
        import torch
        import torch.nn.functional as F
    except ImportError:
        print("torch peer skipped: PyTorch is not installed", file=sys.stderr)
        return None
    if not torch.cuda.is_available():
        print("torch peer skipped: CUDA is not available to PyTorch", file=sys.stderr)
        return None
    torch.backends.cudnn.benchmark = True
    device = torch.cuda.get_device_name()
    event = lambda: torch.cuda.Event(enable_timing=True)  # noqa: E731

    # 1. Copy bandwidth (1 GiB, read + write) and a clone of the image.
    n = 1 << 30
    src = torch.empty(n, dtype=torch.uint8, device="cuda").random_(0, 255)
    dst = torch.empty_like(src)
    us = median_us(lambda: dst.copy_(src), 30, 5, event, torch.cuda.synchronize)
    copy_tb_s = 2.0 * n / (us * 1e-6) / 1e12
    emit({"peer": "torch_copy", "device": device, "torch": torch.__version__, "bytes": n, "median_us": us,
          "copy_tb_s": copy_tb_s}, results)
    del src, dst

    g = torch.Generator(device="cuda")  # PyTorch's fixed default state: the same image every run
    x = (torch.rand(1, C, height, width, device="cuda", generator=g) * 4.0).half()
    us = median_us(lambda: x.clone(), reps, 20, event, torch.cuda.synchronize)
    emit({"peer": "torch_clone", "device": device, "width": width, "height": height, "dtype": "float16",
          "median_us": us, "bytes": 2 * x.numel() * 2}, results)

    # 2. Depthwise conv2d pair, captured in a CUDA graph.
    taps = gaussian_taps(sigma)
    r = len(taps) // 2
    k = torch.tensor(taps, dtype=torch.float64)
    w_h = k.view(1, 1, 1, -1).expand(C, 1, 1, 2 * r + 1).to("cuda", torch.float16).contiguous()
    w_v = k.view(1, 1, -1, 1).expand(C, 1, 2 * r + 1, 1).to("cuda", torch.float16).contiguous()
    out = torch.empty_like(x)

    def blur():
        h = F.conv2d(F.pad(x, (r, r, 0, 0), mode="replicate"), w_h, groups=C)
        out.copy_(F.conv2d(F.pad(h, (0, 0, r, r), mode="replicate"), w_v, groups=C))

    side = torch.cuda.Stream()
    side.wait_stream(torch.cuda.current_stream())
    with torch.cuda.stream(side):
        for _ in range(3):
            blur()
    torch.cuda.current_stream().wait_stream(side)
    torch.cuda.synchronize()
    graph = torch.cuda.CUDAGraph()
    with torch.cuda.graph(graph):
        blur()
    us = median_us(graph.replay, reps, 20, event, torch.cuda.synchronize)
    if not torch.isfinite(out).all():
        raise RuntimeError("non-finite conv2d output")
    emit({"peer": "torch_conv2d", "device": device, "torch": torch.__version__, "width": width, "height": height,
          "dtype": "float16", "sigma": sigma, "taps": 2 * r + 1, "median_us": us}, results)
    return copy_tb_s


def cupy_peer(width, height, sigma, reps, results):
    try:
        import cupy
        import cupyx.scipy.ndimage as ndi
    except ImportError:
        print("cupy peer skipped: CuPy is not installed", file=sys.stderr)
        return
    try:
        if cupy.cuda.runtime.getDeviceCount() < 1:
            raise RuntimeError("no device")
        props = cupy.cuda.runtime.getDeviceProperties(0)
    except Exception as e:  # noqa: BLE001 - any CUDA failure means "no peer here"
        print(f"cupy peer skipped: CUDA is not available to CuPy ({e})", file=sys.stderr)
        return
    device = props["name"].decode() if isinstance(props["name"], bytes) else str(props["name"])
    r = max(1, math.ceil(3.0 * sigma))
    rng = cupy.random.default_rng(1234)
    x = rng.random((height, width, C), dtype=cupy.float32) * 4.0
    out = cupy.empty_like(x)
    # sigma 0 along the channel axis: no mixing of channels. truncate * sigma = R gives 2R + 1 taps.
    run = lambda: ndi.gaussian_filter(x, sigma=(sigma, sigma, 0.0), truncate=r / sigma, mode="nearest",  # noqa
                                      output=out)
    us = median_us(run, reps, 20, lambda: cupy.cuda.Event(), cupy.cuda.Device().synchronize)
    emit({"peer": "cupy_gaussian_filter", "device": device, "cupy": cupy.__version__, "width": width,
          "height": height, "dtype": "float32", "sigma": sigma, "taps": 2 * r + 1, "median_us": us}, results)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="3840x2160", help="WIDTHxHEIGHT")
    ap.add_argument("--sigma", type=float, default=1.2, help="Gaussian sigma in pixels (1.2: 9 taps)")
    ap.add_argument("--reps", type=int, default=200, help="timed runs per peer")
    ap.add_argument("--out", default="blur_torch.json", help="JSON output path")
    args = ap.parse_args()
    width, height = (int(v) for v in args.size.lower().split("x"))

    results = []
    torch_peers(width, height, args.sigma, args.reps, results)
    cupy_peer(width, height, args.sigma, args.reps, results)
    if not results:
        print("no peer could run (need PyTorch or CuPy with CUDA); nothing measured")
        return 0
    with open(args.out, "w") as f:
        json.dump({"size": args.size, "sigma": args.sigma, "results": results}, f, indent=2)
    print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
