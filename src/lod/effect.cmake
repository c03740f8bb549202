# Texture LOD prediction (include/glint/lod.h, docs/LOD.md).
set(GLINT_EFFECT_SOURCES lod.cpp)
set(GLINT_EFFECT_KERNELS
  "shaders/lod_batch|main|"
  "shaders/lod_probe|main|"
  "shaders/lod_probe|explicit|GLINT_PROBE_EXPLICIT_LOD=1"
)
