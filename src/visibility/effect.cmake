# Visibility (docs/OCCLUSION.md): the Hi-Z pyramid and the light cull (include/glint/occlusion.h,
# hiz_pyramid.cpp, light_culler.cpp) and the object cull (include/glint/object_cull.h, object_cull.cpp).
set(GLINT_EFFECT_SOURCES hiz_pyramid.cpp light_culler.cpp object_cull.cpp)
# compact_scan_tiles is the ordered compaction's own first-level scan (the light cull uses it through
# src/core/compaction.h; the shared GLSL is src/core/shaders/compact.glsl).
set(GLINT_EFFECT_KERNELS
  "shaders/hiz_stream|main|"
  "shaders/hiz_stream_texels|main|"
  "shaders/hiz_build|main|"
  "shaders/compact_scan_tiles|main|"
  "shaders/light_cull|main|"
  "shaders/light_cull|one_group|GLINT_CULL_ONE_GROUP=1"
  "shaders/light_cull|from_depth|GLINT_CULL_ONE_GROUP=1+GLINT_CULL_FROM_DEPTH=1"
  "shaders/light_cull_scan|main|"
  "shaders/light_cull_scatter|main|"
  "shaders/object_cull|main|"
  "shaders/object_cull|phase1|GLINT_OBJECT_PHASE1=1"
  "shaders/object_cull|main_subgroup|GLINT_OBJECT_SUBGROUP=1"
  "shaders/object_cull|phase1_subgroup|GLINT_OBJECT_PHASE1=1+GLINT_OBJECT_SUBGROUP=1"
  "shaders/object_cull_v1|main|"
  "shaders/object_cull_scan|main|"
  "shaders/object_cull_scan|main_subgroup|GLINT_OBJECT_SUBGROUP=1"
  "shaders/object_cull_scan|main_serial|GLINT_OBJECT_SUBGROUP=1+GLINT_OBJECT_SCAN_SERIAL=1"
  "shaders/object_cull_scan|main_partial|GLINT_OBJECT_SUBGROUP=1+GLINT_OBJECT_SCAN_PARTIAL=1"
  "shaders/object_cull_scatter|main|"
)
