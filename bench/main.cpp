// glint_bench: Google Benchmark main; the device is chosen by GLINT_DEVICE (index or name).
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
