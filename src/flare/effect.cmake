# Lens flares (include/glint/flare.h, docs/FLARE.md): the flare effect (flare.cpp: setup and checks;
# flare_raster.cpp and flare_compute.cpp: the two draws), the flare pass and the
# layout checks of the GPU types (flare_types_check.cpp).
set(GLINT_EFFECT_SOURCES flare.cpp flare_raster.cpp flare_compute.cpp flare_pass.cpp flare_types_check.cpp)
set(GLINT_EFFECT_KERNELS
  "shaders/flare_atlas|main|"
  "shaders/flare_gather_args|main|"
  "shaders/flare_sprites|main|"
  "shaders/flare_split_plan|main|"
  "shaders/flare_gather|rgba16f|DST_FORMAT=rgba16f"
  "shaders/flare_gather|rgba32f|DST_FORMAT=rgba32f"
  "shaders/flare.vert|main|"
  "shaders/flare.frag|main|"
)
