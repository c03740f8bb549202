#!/usr/bin/env bash
# Validates a kernel after specialization, the way the Vulkan validation layer does
# (VUID-VkPipelineShaderStageCreateInfo-pSpecializationInfo-06719): freeze the specialization
# constants glint uses (workgroup 8x8 and 16x16, constant 2 = 0..2), fold, and run spirv-val.
# spirv-opt has miscompiled vector expressions of gl_WorkGroupSize here, so this runs at build time.
set -euo pipefail
opt=$1 val=$2 spv=$3
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
for wg in 8 16; do
  for c2 in 0 1 2; do
    "$opt" --set-spec-const-default-value "0:$wg 1:$wg 2:$c2" --freeze-spec-const --fold-spec-const-op-composite \
      --eliminate-dead-const "$spv" -o "$tmp"
    "$val" --target-env vulkan1.3 "$tmp" || { echo "$spv: invalid after specialization (workgroup $wg, constant 2 = $c2)" >&2; exit 1; }
  done
done
