"""PyTorch/CUDA peer baseline for glint's object cull benchmark (bench/object_cull_bench.cpp,
BM_ObjectCull with bounds:1, all spheres).

What it measures, on the same machine and in the same session as glint:
  1. The same per-object test as src/visibility/shaders/object_cull.comp for bounding spheres, written as
     elementwise PyTorch float32 on CUDA: view-space centre and distance w, near/far and the four
     side planes of the frustum, the sphere's exact projected x and y bounds from the two tangent
     lines through the eye (Mara & McGuire, JCGT 2013; zeux/niagara's projectSphere), the pixel
     span, the Hi-Z level where the span covers at most 2x2 texels, the four texels of that
     window (one gather from all levels flattened), and the nearest depth against their farthest
     depth. Spheres crossing the near plane are visible without the occlusion test. No fp32
     rounding margins (glint's kernel widens every quantity by its rounding error), so this peer
     is not guaranteed conservative.
  2. The ordered compaction of the visible objects' indices: torch.cumsum of the keep mask gives
     each kept object its slot, scatter_ writes the index there (objects that are not kept write a
     dump slot past the end), and the count stays on the GPU. Test + compaction are captured once
     in a CUDA graph and replayed; each replay timed with CUDA events (median of --reps).
  3. The same compaction by torch.nonzero + the kept count, which synchronises with the host and
     cannot be captured: timed eagerly with CUDA events around each call (median of --reps).
  4. The false-positive share of the first --check objects: those hidden by brute force (the
     exact projected rectangle in float64, every pixel of the depth image under it) that the
     test keeps, over those hidden, the quantity of BM_ObjectCull's false_positive_share; and the
     false negatives among them (brute-force visible, culled: possible here, never in glint).

The scene follows BM_ObjectCull: 1920x1080 depth, identity view, a Vulkan perspective (vertical
field of view 1 rad, near 0.1, far 100, standard Z, y flipped), spheres at distance 0.5 to 60.5
spread over 1.2x the view volume with radius d * 0.02 * u * u. The depth image is this script's
own (random axis-aligned occluder rectangles over the far plane, seeded), not glint's generator:
times compare, false-positive shares only roughly.

Usage: python3 bench/peers/object_cull_torch.py [--objects 1000000,10000000] [--reps 200]
                                                [--check 4096] [--out object_cull_torch.json]
Prints a table and writes JSON:
  {"device", "torch", "width", "height",
   "object_cull": [{"objects", "method", "peer", "median_us", "visible_share", "occluded_share",
                    "false_positive_share", "checked_hidden", "false_negatives"}, ...]}
Exits with status 0 and a message when PyTorch or CUDA is not available (--device cpu runs the
same code on the CPU for a smoke test; its times mean nothing).
"""
import argparse
import json
import math
import sys

try:
    import torch
    import torch.nn.functional as F
except ImportError:  # no torch, no failure (as the other peers)
    print("object_cull_torch.py: PyTorch is not installed; no peer numbers", file=sys.stderr)
    sys.exit(0)

from peer_timing import timed_eager, timed_graph  # noqa: E402 (after the torch guard)

WIDTH, HEIGHT = 1920, 1080
FOV_Y, NEAR, FAR = 1.0, 0.1, 100.0


def projection():
    """The non-zero terms of glint's reference::perspective(1, W/H, 0.1, 100, standard Z, flip y)."""
    f = 1.0 / math.tan(FOV_Y / 2.0)
    p00 = f / (WIDTH / HEIGHT)
    p11 = -f  # y flipped
    # depth = a + b / w with w = -z_view: a = far / (far - near), b = near far / (near - far).
    a = FAR / (FAR - NEAR)
    b = NEAR * FAR / (NEAR - FAR)
    return p00, p11, a, b


def make_objects(n, gen, dev):
    """Spheres as BM_ObjectCull places them (view space: camera at the origin looking down -z)."""
    u = lambda: torch.rand(n, generator=gen, device=dev)  # noqa: E731
    d = 0.5 + 60.0 * u()
    x = (u() * 2.4 - 1.2) * d
    y = (u() * 2.4 - 1.2) * d
    r = d * 0.02 * u() * u()
    return torch.stack([x, y, -d, r], dim=1).contiguous()


def make_depth(gen, dev, rects=400):
    """A standard-Z depth image: far plane (1.0) with random flat occluder rectangles nearer."""
    _, _, a, b = projection()
    depth = torch.ones((HEIGHT, WIDTH), device=dev)
    r = torch.rand((rects, 5), generator=gen).tolist()  # on the host: a handful of slices
    for x0, y0, sw, sh, dd in r:
        w = 1.0 + 40.0 * dd
        x, y = int(x0 * WIDTH), int(y0 * HEIGHT)
        ww, hh = int(20 + sw * WIDTH / 4), int(20 + sh * HEIGHT / 4)
        z = a + b / w
        view = depth[y:y + hh, x:x + ww]
        view.copy_(torch.minimum(view, torch.full_like(view, z)))  # nearer wins
    return depth


def hiz_levels(depth):
    """glint's pyramid: level k is max(1, size >> k) on a side and texel c holds the farthest depth
    of pixels [c 2^k, (c + 1) 2^k), the last texel up to the edge (an odd row or column folds into
    the last texel). Returns [level 0 = depth, level 1, ...] with floor(log2(max(W, H))) levels."""
    levels = [depth]
    count = int(math.floor(math.log2(max(WIDTH, HEIGHT))))
    x = depth
    for _ in range(count):
        h, w = x.shape
        y = F.max_pool2d(x[None, None], kernel_size=2, stride=2, ceil_mode=True)[0, 0]
        if w > 1 and w % 2 == 1:
            y = torch.cat([y[:, :-2], torch.maximum(y[:, -2:-1], y[:, -1:])], dim=1)
        if h > 1 and h % 2 == 1:
            y = torch.cat([y[:-2], torch.maximum(y[-2:-1], y[-1:])], dim=0)
        levels.append(y.contiguous())
        x = y
    return levels


class SphereCull:
    """The test and the ordered compaction on fixed buffers (graph-capturable)."""

    def __init__(self, objects, levels):
        dev = objects.device
        self.objects = objects
        self.n = objects.shape[0]
        self.flat = torch.cat([lv.reshape(-1) for lv in levels])
        sizes = [(lv.shape[1], lv.shape[0]) for lv in levels]
        offsets, at = [], 0
        for w, h in sizes:
            offsets.append(at)
            at += w * h
        self.offset = torch.tensor(offsets, device=dev, dtype=torch.int64)
        self.lw = torch.tensor([w for w, _ in sizes], device=dev, dtype=torch.int64)
        self.lh = torch.tensor([h for _, h in sizes], device=dev, dtype=torch.int64)
        self.top = len(levels) - 1
        self.out = torch.empty(self.n + 1, device=dev, dtype=torch.int64)  # last: dump slot
        self.count = torch.zeros((), device=dev, dtype=torch.int64)
        self.state = torch.empty(self.n, device=dev, dtype=torch.int8)
        self.index = torch.arange(self.n, device=dev, dtype=torch.int64)
        self.states = torch.tensor([1, 2, 3], device=dev, dtype=torch.int64)  # visible, occluded, frustum

    def test(self):
        """State per object: 1 visible, 2 occluded, 3 frustum (glint's numbering)."""
        p00, p11, a, b = projection()
        o = self.objects
        cx, cy, w, r = o[:, 0], o[:, 1], -o[:, 2], o[:, 3]
        lx = math.sqrt(p00 * p00 + 1.0)
        ly = math.sqrt(p11 * p11 + 1.0)
        outside = (w - r > FAR) | (w + r < NEAR)
        outside |= (p00 * cx + w < -r * lx) | (-p00 * cx + w < -r * lx)
        outside |= (p11 * cy + w < -r * ly) | (-p11 * cy + w < -r * ly)
        crossing = w - r < NEAR
        wr = torch.clamp(w - r, min=NEAR)  # only used where w - r >= near

        def slopes(c):
            t = torch.sqrt(torch.clamp(c * c + (w - r) * (w + r), min=0.0))
            return (t * c - r * w) / (t * w + r * c), (t * c + r * w) / (t * w - r * c)

        sx0, sx1 = slopes(cx)
        sy0, sy1 = slopes(cy)
        nx0, nx1 = p00 * sx0, p00 * sx1
        ny0, ny1 = p11 * sy0, p11 * sy1
        x_lo, x_hi = torch.minimum(nx0, nx1), torch.maximum(nx0, nx1)
        y_lo, y_hi = torch.minimum(ny0, ny1), torch.maximum(ny0, ny1)
        px0 = torch.clamp((x_lo * 0.5 + 0.5) * WIDTH, 0.0, WIDTH)
        px1 = torch.clamp((x_hi * 0.5 + 0.5) * WIDTH, 0.0, WIDTH)
        py0 = torch.clamp((y_lo * 0.5 + 0.5) * HEIGHT, 0.0, HEIGHT)
        py1 = torch.clamp((y_hi * 0.5 + 0.5) * HEIGHT, 0.0, HEIGHT)
        p0x = torch.clamp(torch.floor(px0).long(), max=WIDTH - 1)
        p0y = torch.clamp(torch.floor(py0).long(), max=HEIGHT - 1)
        p1x = torch.maximum(torch.ceil(px1).long() - 1, p0x).clamp(max=WIDTH - 1)
        p1y = torch.maximum(torch.ceil(py1).long() - 1, p0y).clamp(max=HEIGHT - 1)
        span = torch.maximum(p1x - p0x, p1y - p0y) + 1
        # Smallest k with 2^k >= span - 1 (0 for span <= 2), capped by the levels built.
        k = torch.where(span <= 2, torch.zeros_like(span),
                        torch.ceil(torch.log2((span - 1).clamp(min=1).double())).long())
        k = k.clamp(max=self.top)
        lw, lh, off = self.lw[k], self.lh[k], self.offset[k]
        t0x = torch.minimum(p0x >> k, lw - 1)
        t0y = torch.minimum(p0y >> k, lh - 1)
        t1x = torch.minimum(p1x >> k, lw - 1)
        t1y = torch.minimum(p1y >> k, lh - 1)
        d = torch.stack([self.flat[off + t0y * lw + t0x], self.flat[off + t0y * lw + t1x],
                         self.flat[off + t1y * lw + t0x], self.flat[off + t1y * lw + t1x]], dim=1)
        z = a + b / wr
        visible = (d >= z[:, None]).any(dim=1) | crossing
        state = torch.where(visible, self.states[0], self.states[1])
        state = torch.where(outside, self.states[2], state)
        return state

    def run_cumsum(self):
        """Test, then the ordered compaction by cumsum + scatter_ (no host synchronisation)."""
        state = self.test()
        keep = state == 1
        slot = torch.cumsum(keep, dim=0) - 1
        target = torch.where(keep, slot, self.n)
        self.out.scatter_(0, target, self.index)
        self.count.copy_(slot[-1] + 1)
        self.state.copy_(state)

    def run_nonzero(self):
        """Test, then the ordered compaction by nonzero (synchronises with the host)."""
        state = self.test()
        idx = torch.nonzero(state == 1, as_tuple=False).squeeze(1)
        self.out[: idx.numel()].copy_(idx)
        self.count.fill_(idx.numel())
        self.state.copy_(state)


def brute_hidden(objects, depth, count):
    """Brute force for the first `count` spheres in float64: frustum planes without margins, near
    crossing visible, else the exact projected rectangle read at every pixel of the depth image."""
    p00, p11, a, b = projection()
    o = objects[:count].double().cpu()
    dep = depth.cpu()
    lx, ly = math.sqrt(p00 * p00 + 1.0), math.sqrt(p11 * p11 + 1.0)
    hidden = []
    for cx, cy, cz, r in o.tolist():
        w = -cz
        if (w - r > FAR or w + r < NEAR or p00 * cx + w < -r * lx or -p00 * cx + w < -r * lx
                or p11 * cy + w < -r * ly or -p11 * cy + w < -r * ly):
            hidden.append(True)
            continue
        if w - r < NEAR:
            hidden.append(False)
            continue
        ext = []
        for c, s, size in ((cx, p00, WIDTH), (cy, p11, HEIGHT)):
            t = math.sqrt(max(c * c + (w - r) * (w + r), 0.0))
            lo, hi = s * (t * c - r * w) / (t * w + r * c), s * (t * c + r * w) / (t * w - r * c)
            lo, hi = min(lo, hi), max(lo, hi)
            p0 = min(max(math.floor((lo * 0.5 + 0.5) * size), 0), size - 1)
            p1 = min(max(math.ceil((hi * 0.5 + 0.5) * size) - 1, p0), size - 1)
            ext.append((p0, p1))
        (x0, x1), (y0, y1) = ext
        z = a + b / (w - r)
        hidden.append(not bool((dep[y0:y1 + 1, x0:x1 + 1].double() >= z).any()))
    return torch.tensor(hidden)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--objects", default="1000000,10000000")
    ap.add_argument("--reps", type=int, default=200)
    ap.add_argument("--check", type=int, default=4096, help="objects checked against brute force")
    ap.add_argument("--device", default="cuda", help="cuda (default) or cpu (smoke test only)")
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    if args.device == "cuda" and not torch.cuda.is_available():
        print("object_cull_torch.py: CUDA is not available to PyTorch; no peer numbers", file=sys.stderr)
        return 0
    dev = torch.device(args.device)
    name = torch.cuda.get_device_name(0) if dev.type == "cuda" else "cpu"
    results = {"device": name, "torch": torch.__version__, "width": WIDTH, "height": HEIGHT, "object_cull": []}
    gen = torch.Generator(device="cpu").manual_seed(2024)
    depth = make_depth(gen, torch.device("cpu")).to(dev)
    levels = hiz_levels(depth)
    print(f"device: {name}  torch {torch.__version__}  {WIDTH}x{HEIGHT}, {len(levels) - 1} Hi-Z levels")
    print(f"{'objects':>9} {'method':<26} {'median us':>10} {'visible':>8} {'occluded':>9} {'fp share':>9} "
          f"{'missed':>6}")
    for n in (int(v) for v in args.objects.split(",")):
        ogen = torch.Generator(device="cpu").manual_seed(7)
        objects = make_objects(n, ogen, torch.device("cpu")).to(dev)
        cull = SphereCull(objects, levels)
        hidden = brute_hidden(objects, depth, min(n, args.check))
        methods = [("sphere+hiz, cumsum, graph", cull.run_cumsum, True),
                   ("sphere+hiz, nonzero, eager", cull.run_nonzero, False)]
        for label, fn, graph in methods:
            if graph and dev.type == "cuda":
                ms = timed_graph(fn, args.reps)
            else:
                ms = timed_eager(fn, args.reps, dev.type == "cuda")
            fn()  # the outputs of one more run, for the shares and the check
            state = cull.state.long().cpu()
            count = int(cull.count)
            kept = cull.out[:count].cpu()
            expect = torch.nonzero(state == 1, as_tuple=False).squeeze(1)
            if not torch.equal(kept, expect):
                raise SystemExit(f"{label}: the list is not the visible objects in order")
            m = min(n, args.check)
            fp = int(((state[:m] == 1) & hidden).sum())
            fn = int(((state[:m] != 1) & ~hidden).sum())  # no margins: this peer may miss objects
            row = {"objects": n, "method": label, "peer": f"PyTorch {label}", "median_us": ms * 1e3,
                   "visible_share": float((state == 1).double().mean()),
                   "occluded_share": float((state == 2).double().mean()),
                   "false_positive_share": fp / max(1, int(hidden.sum())), "checked_hidden": int(hidden.sum()),
                   "false_negatives": fn}
            results["object_cull"].append(row)
            print(f"{n:>9} {label:<26} {row['median_us']:>10.1f} {row['visible_share']:>8.3f} "
                  f"{row['occluded_share']:>9.3f} {row['false_positive_share']:>9.4f} {fn:>6}")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=2)
        print("wrote", args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
