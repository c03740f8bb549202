# Bloom (include/glint/bloom.h, docs/BLOOM.md). image_copy is bloom's: what it records at
# intensity 0 (it takes BloomPush).
set(GLINT_EFFECT_SOURCES bloom.cpp)
set(GLINT_EFFECT_KERNELS
  "shaders/bloom_prefilter_down|rgba16f|DST_FORMAT=rgba16f"
  "shaders/bloom_prefilter_down|rgba32f|DST_FORMAT=rgba32f"
  "shaders/bloom_prefilter_smooth|rgba16f|DST_FORMAT=rgba16f"
  "shaders/bloom_prefilter_smooth|rgba32f|DST_FORMAT=rgba32f"
  "shaders/bloom_prefilter_boxes|rgba16f|DST_FORMAT=rgba16f"
  "shaders/bloom_prefilter_boxes|rgba32f|DST_FORMAT=rgba32f"
  "shaders/bloom_down|rgba16f|DST_FORMAT=rgba16f"
  "shaders/bloom_down|rgba32f|DST_FORMAT=rgba32f"
  "shaders/bloom_blur|rgba16f|DST_FORMAT=rgba16f"
  "shaders/bloom_blur|rgba32f|DST_FORMAT=rgba32f"
  "shaders/bloom_up|rgba16f|DST_FORMAT=rgba16f"
  "shaders/bloom_up|rgba32f|DST_FORMAT=rgba32f"
  "shaders/bloom_composite|rgba16f|DST_FORMAT=rgba16f+OUTPUT_MAX=65504.0"
  "shaders/bloom_composite|rgba32f|DST_FORMAT=rgba32f+OUTPUT_MAX=3.4028234e38"
  "shaders/bloom_composite|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f+OUTPUT_MAX=65024.0"
  "shaders/bloom_composite|noformat|OUTPUT_MAX=65504.0"
  "shaders/image_copy|rgba16f|DST_FORMAT=rgba16f"
  "shaders/image_copy|rgba32f|DST_FORMAT=rgba32f"
  "shaders/image_copy|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/image_copy|noformat|"
)
