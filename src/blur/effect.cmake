# Blur (include/glint/blur.h, docs/BLUR.md): the planner (blur_plan.h: taps, error model, cost model,
# border padding, plans), the cost model's measurement (blur_calibration) and the driver.
set(GLINT_EFFECT_SOURCES gaussian_blur.cpp blur_pyramid.cpp blur_steps.cpp blur_plan.cpp blur_taps.cpp blur_error_model.cpp blur_cost_model.cpp blur_border.cpp
                          blur_calibration.cpp)
set(GLINT_EFFECT_KERNELS
  "shaders/blur_level|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_level|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_level|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_level|noformat|"
  "shaders/blur_line|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_line|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_line|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_line|noformat|"
  "shaders/blur_linear|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_linear|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_linear|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_linear|noformat|"
  "shaders/blur_upsample|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_upsample|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_upsample|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_upsample|noformat|"
  "shaders/blur_down|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_down|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_down|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_down|noformat|"
  "shaders/blur_dual_down|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_dual_down|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_dual_down|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_dual_down|noformat|"
  "shaders/blur_dual_up|rgba16f|DST_FORMAT=rgba16f"
  "shaders/blur_dual_up|rgba32f|DST_FORMAT=rgba32f"
  "shaders/blur_dual_up|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "shaders/blur_dual_up|noformat|"
)
