"""PyTorch/CUDA peer baseline for glint's Vulkan bloom benchmark (bench/bloom_bench.cpp).

What it measures, on the same machine and in the same session as glint:
  1. Device-to-device copy bandwidth: a 1 GiB `dst.copy_(src)`, median of >= 20 timed copies,
     reported in TB/s counting bytes read + bytes written (2 * size / time). This is the
     "achievable bandwidth" against which bytes-moved floors are turned into floor times.
  2. A bloom chain close to glint's default (cod13, fp16 levels), written in PyTorch fp16 on
     CUDA, NCHW, batch 1, RGBA (alpha passes through untouched):
       a. soft-knee bright pass at full resolution (threshold 1.0, soft knee 0.5);
       b. 5 downsample levels, each the Call-of-Duty 13-tap filter, which for an exact 2:1
          reduction is a fixed 6x6 stride-2 depthwise convolution (replicate edges);
       c. upsample from the smallest level: bilinear 2x then a 3x3 tent, A_k = L_k + up(A_k+1);
       d. composite: out = scene + intensity / 5 * up(A_0), intensity 0.3.
     The whole chain is captured once in a CUDA graph and replayed, so launch overhead is as
     low as PyTorch gets; each replay is timed with CUDA events (median of --reps).
  3. glint's bytes-moved floor for RGBA16F in/out and fp16 levels,
     W*H*(8+8) + sum over the 5 levels of 2*w*h*8, and that floor over the measured copy
     bandwidth (the floor time).

Why: this is the peer number for docs/PERF.md. Figures quoted for a similar chain (243 us at
1080p and 893 us at 2160p on an H100) come from other machines and sessions; this script
reproduces such a peer in the same session as glint
so the comparison is like for like (same GPU, same clocks, same driver).

Usage: python3 bench/peers/bloom_torch.py [--sizes 1920x1080,3840x2160] [--reps 200]
                                          [--out bloom_torch.json]
"""
import argparse
import json
import statistics
import sys

import torch
import torch.nn.functional as F

LEVELS = 5
THRESHOLD, SOFT_KNEE, INTENSITY = 1.0, 0.5, 0.3
C = 4  # RGBA


def copy_bandwidth_tb_s(reps=30):
    n = 1 << 30
    src = torch.empty(n, dtype=torch.uint8, device="cuda").random_(0, 255)
    dst = torch.empty_like(src)
    for _ in range(5):
        dst.copy_(src)
    torch.cuda.synchronize()
    times = []
    for _ in range(reps):
        a, b = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
        a.record()
        dst.copy_(src)
        b.record()
        b.synchronize()
        times.append(a.elapsed_time(b) * 1e-3)  # seconds
    return 2.0 * n / statistics.median(times) / 1e12


def cod13_kernel():
    """6x6 weights of the 13-tap filter for an exact 2:1 reduction.

    Output texel i covers source texels 2i, 2i+1; its centre is the corner between them. A tap at
    offset o (texels, o in -2..2) from that corner is a bilinear fetch at a texel corner, i.e. the
    mean of source texels 2i+o and 2i+o+1, which are kernel indices o+2 and o+3 (index 0 = 2i-2).
    """
    k = torch.zeros(6, 6, dtype=torch.float64)
    taps = {}
    # Centre box: the four (+-1, +-1) taps, 0.5 in total.
    for o in [(-1, -1), (1, -1), (-1, 1), (1, 1)]:
        taps[o] = taps.get(o, 0.0) + 0.5 / 4
    # Four corner boxes of 2x2 taps on the {-2,0,2} grid, 0.125 each.
    for bx in (-2, 0):
        for by in (-2, 0):
            for o in [(bx, by), (bx + 2, by), (bx, by + 2), (bx + 2, by + 2)]:
                taps[o] = taps.get(o, 0.0) + 0.125 / 4
    for (ox, oy), w in taps.items():
        k[oy + 2:oy + 4, ox + 2:ox + 4] += w / 4
    assert abs(k.sum().item() - 1.0) < 1e-12
    return k


class BloomChain:
    def __init__(self, width, height):
        dev, dt = "cuda", torch.float16
        self.w_down = cod13_kernel().to(dev, dt).expand(C, 1, 6, 6).contiguous()
        tent = torch.tensor([1.0, 2.0, 1.0], dtype=torch.float64)
        tent = torch.outer(tent, tent) / 16.0
        self.w_tent = tent.to(dev, dt).expand(C, 1, 3, 3).contiguous()
        # Final tent also applies intensity/5 to RGB and zeroes alpha so alpha passes untouched.
        scale = torch.tensor([INTENSITY / LEVELS] * 3 + [0.0], dtype=torch.float64).view(C, 1, 1, 1)
        self.w_final = (tent.view(1, 1, 3, 3) * scale).to(dev, dt).contiguous()
        self.luma = torch.tensor([0.2126, 0.7152, 0.0722], device=dev, dtype=dt).view(1, 3, 1, 1)
        self.sizes = []  # (w, h) of each level
        w, h = width, height
        for _ in range(LEVELS):
            w, h = w // 2, h // 2
            if w < 1 or h < 1:
                raise ValueError(f"{width}x{height} too small for {LEVELS} levels")
            self.sizes.append((w, h))

    def bright(self, x):
        knee = THRESHOLD * SOFT_KNEE
        lum = (x[:, :3] * self.luma).sum(dim=1, keepdim=True)
        soft = torch.clamp(lum - THRESHOLD + knee, 0.0, 2.0 * knee)
        contrib = soft * soft / (4.0 * knee + 1e-4)
        factor = torch.maximum(lum - THRESHOLD, contrib) / torch.clamp(lum, min=1e-4)
        return x * factor  # alpha is scaled too but never reaches the output (w_final zeroes it)

    def down(self, x, size):
        w, h = size
        y = F.conv2d(F.pad(x, (2, 2, 2, 2), mode="replicate"), self.w_down, stride=2, groups=C)
        return y[:, :, :h, :w]

    def up(self, x, hw, weight):
        y = F.interpolate(x, size=hw, mode="bilinear", align_corners=False)
        return F.conv2d(F.pad(y, (1, 1, 1, 1), mode="replicate"), weight, groups=C)

    def __call__(self, scene, out):
        levels = []
        x = self.bright(scene)
        for size in self.sizes:
            x = self.down(x, size)
            levels.append(x)
        acc = levels[-1]
        for k in range(LEVELS - 2, -1, -1):
            w, h = self.sizes[k]
            acc = levels[k] + self.up(acc, (h, w), self.w_tent)
        bloom = self.up(acc, tuple(scene.shape[2:]), self.w_final)
        torch.add(scene, bloom, out=out)
        return out


def random_hdr(width, height):
    # A new generator starts from PyTorch's fixed default state, so every run draws the same image.
    g = torch.Generator(device="cuda")
    x = torch.rand(1, C, height, width, device="cuda", generator=g) * 2.0
    hot = torch.rand(1, 1, height, width, device="cuda", generator=g) < 0.02
    hot_val = 20.0 + 30.0 * torch.rand(1, 3, height, width, device="cuda", generator=g)
    x[:, :3] = torch.where(hot, hot_val, x[:, :3])
    x[:, 3] = 1.0
    return x.half()


def floor_bytes(width, height):
    total, w, h = width * height * (8 + 8), width, height
    for _ in range(LEVELS):
        w, h = w // 2, h // 2
        total += 2 * w * h * 8
    return total


def time_bloom(width, height, reps, warmup=20):
    chain = BloomChain(width, height)
    static_in = random_hdr(width, height)
    static_out = torch.empty_like(static_in)
    side = torch.cuda.Stream()
    side.wait_stream(torch.cuda.current_stream())
    with torch.cuda.stream(side):
        for _ in range(3):
            chain(static_in, static_out)
    torch.cuda.current_stream().wait_stream(side)
    torch.cuda.synchronize()
    graph = torch.cuda.CUDAGraph()
    with torch.cuda.graph(graph):
        chain(static_in, static_out)
    for _ in range(warmup):
        graph.replay()
    torch.cuda.synchronize()
    events = [(torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)) for _ in range(reps)]
    for a, b in events:
        a.record()
        graph.replay()
        b.record()
    torch.cuda.synchronize()
    if not torch.isfinite(static_out).all():
        raise RuntimeError(f"non-finite bloom output at {width}x{height}")
    return statistics.median([a.elapsed_time(b) * 1e3 for a, b in events])  # us


def parse_sizes(text):
    sizes = []
    for item in text.split(","):
        w, h = item.lower().strip().split("x")
        sizes.append((int(w), int(h)))
    return sizes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="640x480,1920x1080,3840x2160", help="e.g. 1920x1080,3840x2160")
    ap.add_argument("--reps", type=int, default=200, help="timed graph replays per size")
    ap.add_argument("--out", default="bloom_torch.json", help="JSON output path")
    args = ap.parse_args()
    if not torch.cuda.is_available():
        sys.exit("error: CUDA is not available to PyTorch; this peer benchmark needs an NVIDIA GPU")
    torch.backends.cudnn.benchmark = True
    device = torch.cuda.get_device_name()

    copy = copy_bandwidth_tb_s()
    results = []
    for w, h in parse_sizes(args.sizes):
        us = time_bloom(w, h, args.reps)
        fb = floor_bytes(w, h)
        floor_us = fb / (copy * 1e12) * 1e6
        results.append({"width": w, "height": h, "median_us": us, "floor_bytes": fb,
                        "floor_us": floor_us, "floor_over_median": floor_us / us})

    print(f"device: {device}  torch {torch.__version__}  copy bandwidth (read+write): {copy:.3f} TB/s")
    print(f"{'size':>11} {'median us':>10} {'floor MB':>9} {'floor us':>9} {'floor/median':>12}")
    for r in results:
        print(f"{r['width']:>5}x{r['height']:<5} {r['median_us']:>10.1f} {r['floor_bytes'] / 1e6:>9.2f} "
              f"{r['floor_us']:>9.1f} {r['floor_over_median']:>12.3f}")
    with open(args.out, "w") as f:
        json.dump({"device": device, "torch": torch.__version__, "copy_tb_s": copy, "bloom": results}, f, indent=2)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
