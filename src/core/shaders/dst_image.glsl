// The binding layout of the image a kernel writes for the caller. The variants listed in
// each effect's effect.cmake define DST_FORMAT as the GLSL format qualifier matching the view's format
// (rgba16f, rgba32f, r11f_g11f_b10f): the compatibility table of the Vulkan spec ("Compatibility
// Between SPIR-V Image Formats and Vulkan Formats") requires an exact match. The "noformat"
// variant defines none: the image has format Unknown, which Vulkan 1.3 lets a kernel write where
// the view's format has VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT (the host checks).
#ifdef DST_FORMAT
#define DST_LAYOUT(b) layout(binding = b, DST_FORMAT)
#else
#define DST_LAYOUT(b) layout(binding = b)
#endif
