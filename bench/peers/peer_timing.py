"""GPU timing shared by the PyTorch peers (occlusion_torch.py, object_cull_torch.py): the median of
CUDA event pairs around each run, after three warm-up runs, as glint_bench takes the median of its
timestamp pairs. Import it after torch (the peers exit cleanly when torch is missing)."""
import statistics
import time

import torch


def timed_graph(fn, reps):
    """Median milliseconds of replays of `fn` captured in a CUDA graph (no launch overhead per op)."""
    stream = torch.cuda.Stream()
    stream.wait_stream(torch.cuda.current_stream())
    with torch.cuda.stream(stream):
        for _ in range(3):  # warm up before capture
            fn()
    torch.cuda.current_stream().wait_stream(stream)
    graph = torch.cuda.CUDAGraph()
    with torch.cuda.graph(graph):
        fn()
    return _median_ms(graph.replay, reps)


def timed_eager(fn, reps, cuda=True):
    """Median milliseconds of `fn` run eagerly; on a CPU device (cuda False), wall time."""
    for _ in range(3):
        fn()
    if not cuda:
        times = []
        for _ in range(reps):
            t = time.perf_counter()
            fn()
            times.append((time.perf_counter() - t) * 1e3)
        return statistics.median(times)
    torch.cuda.synchronize()
    return _median_ms(fn, reps)


def _median_ms(run, reps):
    times = []
    for _ in range(reps):
        start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
        start.record()
        run()
        end.record()
        torch.cuda.synchronize()
        times.append(start.elapsed_time(end))
    return statistics.median(times)
