#!/usr/bin/env bash
# Runs glint_bench with exactly the benchmarks each chart of docs/charts/ draws, one JSON per chart:
#
#   bench/chart_data.sh [--cpu] BENCH_BINARY OUT_DIR [CHART ...]
#
# CHART is bloom, blur, occlusion or object_cull (default: all four); OUT_DIR/CHART.json is written
# (Google Benchmark JSON, medians of 3 repetitions). The glint commit is recorded in the JSON's
# context as glint_commit (from $GLINT_COMMIT, else `git rev-parse --short HEAD`, else "unknown");
# bench/plot.py puts it in the caption. The device is the one glint_bench picks (GLINT_DEVICE).
#
# GPU filters (about 5 minutes on an H100 in all): bloom at 1920x1080, every filter, guard and
# fp32 variant; the Gaussian blur methods at 3840x2160, sigma 1.2 to 64; the light cull at 1,000,000
# lights for N = 1, 4, 8, 16 (default multi-jittered pattern) and N = 4 regular; the object cull.
# --cpu takes the blur at 960x540 instead, for CPU devices (lavapipe: about 15 minutes on 2 loaded
# cores for bloom, blur and occlusion).
set -euo pipefail

cpu=0
if [[ "${1:-}" == "--cpu" ]]; then
  cpu=1
  shift
fi
if [[ $# -lt 2 ]]; then
  sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
bench=$1
out=$2
shift 2
charts=("$@")
if [[ ${#charts[@]} -eq 0 ]]; then charts=(bloom blur occlusion object_cull); fi

commit=${GLINT_COMMIT:-$(git -C "$(dirname "$0")" rev-parse --short HEAD 2>/dev/null || echo unknown)}
mkdir -p "$out"

filter_for() {
  case "$1:$cpu" in
    bloom:*) echo 'BM_Bloom/w:1920/h:1080/.*/fused:0/' ;;
    blur:0) echo 'BM_Blur(Separable|SeparableLinear|Pyramid|Dual|Auto)/sigma10:[0-9]+/w:3840/h:2160/' ;;
    blur:1) echo 'BM_Blur(Separable|SeparableLinear|Pyramid|Dual|Auto)/sigma10:[0-9]+/w:960/h:540/' ;;
    occlusion:*) echo 'BM_LightCull/n:1000000/grid:[0-9]+/results:0/hiz:0/pattern:[01]/' ;;
    object_cull:*) echo 'BM_ObjectCull' ;;
    *)
      echo "unknown chart '$1' (bloom, blur, occlusion, object_cull)" >&2
      return 1
      ;;
  esac
}

for chart in "${charts[@]}"; do filter_for "$chart" >/dev/null; done # refuse a bad name before running

for chart in "${charts[@]}"; do
  filter=$(filter_for "$chart")
  echo "== $chart: --benchmark_filter='$filter' -> $out/$chart.json" >&2
  start=$(date +%s)
  "$bench" --benchmark_filter="$filter" --benchmark_min_time=0.05 --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true --benchmark_out_format=json --benchmark_out="$out/$chart.json" \
    --benchmark_context=glint_commit="$commit"
  echo "== $chart took $(($(date +%s) - start)) s" >&2
done
