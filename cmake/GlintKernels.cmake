# Compiles every kernel to SPIR-V for Vulkan 1.3 at build time, checks it with spirv-val and
# embeds it in the library as uint32_t arrays. Kernels that write an image are compiled once per
# storage format (rgba16f, rgba32f), since lavapipe lacks shaderStorageImageReadWithoutFormat.
# Kernels that write the caller's output (bloom composite, image copy, the blur kernels) also get
# r11f_g11f_b10f (VK_FORMAT_B10G11R11_UFLOAT_PACK32) and noformat: no qualifier, for the other
# float colour formats whose format features include STORAGE_WRITE_WITHOUT_FORMAT
# (kernels/common/dst_image.glsl, host/core/formats.h).
# Kernels include their private headers from common/ and the installed GLSL/C++ shared headers as
# "glint/gpu/..." from include/ (the same files engines get).
file(GLOB GLINT_KERNEL_HEADERS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/common/*
     ${PROJECT_SOURCE_DIR}/include/glint/gpu/*)

# name;defines... one entry per variant: KERNEL|VARIANT|DEFINES (defines separated by '+').
# KERNEL without an extension compiles KERNEL.comp and gets the id KERNEL_VARIANT; a graphics stage
# is listed with its file name (flare.vert, flare.frag) and gets the id KERNEL_STAGE_VARIANT
# (flare_vert_main). Only compute kernels take the specialization check (check_specialized.sh):
# the graphics stages have no workgroup constants.
set(GLINT_KERNEL_VARIANTS
  "bloom_prefilter_down|rgba16f|DST_FORMAT=rgba16f"
  "bloom_prefilter_down|rgba32f|DST_FORMAT=rgba32f"
  "bloom_prefilter_smooth|rgba16f|DST_FORMAT=rgba16f"
  "bloom_prefilter_smooth|rgba32f|DST_FORMAT=rgba32f"
  "bloom_down|rgba16f|DST_FORMAT=rgba16f"
  "bloom_down|rgba32f|DST_FORMAT=rgba32f"
  "bloom_blur|rgba16f|DST_FORMAT=rgba16f"
  "bloom_blur|rgba32f|DST_FORMAT=rgba32f"
  "bloom_up|rgba16f|DST_FORMAT=rgba16f"
  "bloom_up|rgba32f|DST_FORMAT=rgba32f"
  "bloom_composite|rgba16f|DST_FORMAT=rgba16f+OUTPUT_MAX=65504.0"
  "bloom_composite|rgba32f|DST_FORMAT=rgba32f+OUTPUT_MAX=3.4028234e38"
  "bloom_composite|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f+OUTPUT_MAX=65024.0"
  "bloom_composite|noformat|OUTPUT_MAX=65504.0"
  "image_copy|rgba16f|DST_FORMAT=rgba16f"
  "image_copy|rgba32f|DST_FORMAT=rgba32f"
  "image_copy|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "image_copy|noformat|"
  "demo_starfield|rgba16f|DST_FORMAT=rgba16f"
  "demo_starfield|rgba32f|DST_FORMAT=rgba32f"
  "blur_level|rgba16f|DST_FORMAT=rgba16f"
  "blur_level|rgba32f|DST_FORMAT=rgba32f"
  "blur_level|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "blur_level|noformat|"
  "blur_line|rgba16f|DST_FORMAT=rgba16f"
  "blur_line|rgba32f|DST_FORMAT=rgba32f"
  "blur_line|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "blur_line|noformat|"
  "blur_linear|rgba16f|DST_FORMAT=rgba16f"
  "blur_linear|rgba32f|DST_FORMAT=rgba32f"
  "blur_linear|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "blur_linear|noformat|"
  "blur_upsample|rgba16f|DST_FORMAT=rgba16f"
  "blur_upsample|rgba32f|DST_FORMAT=rgba32f"
  "blur_upsample|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "blur_upsample|noformat|"
  "blur_dual_down|rgba16f|DST_FORMAT=rgba16f"
  "blur_dual_down|rgba32f|DST_FORMAT=rgba32f"
  "blur_dual_down|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "blur_dual_down|noformat|"
  "blur_dual_up|rgba16f|DST_FORMAT=rgba16f"
  "blur_dual_up|rgba32f|DST_FORMAT=rgba32f"
  "blur_dual_up|r11f_g11f_b10f|DST_FORMAT=r11f_g11f_b10f"
  "blur_dual_up|noformat|"
  "lod_batch|main|"
  "lod_probe|main|"
  "lod_probe|explicit|GLINT_PROBE_EXPLICIT_LOD=1"
  "hiz_build|main|"
  "light_cull|main|"
  "light_cull_scan|main|"
  "light_cull_scan_tiles|main|"
  "light_cull_scatter|main|"
  "object_cull|main|"
  "object_cull|phase1|GLINT_OBJECT_PHASE1=1"
  "object_cull_scan|main|"
  "object_cull_scan_tiles|main|"
  "object_cull_scatter|main|"
  "flare_atlas|main|"
  "flare_gather_args|main|"
  "flare_gather|rgba16f|DST_FORMAT=rgba16f"
  "flare_gather|rgba32f|DST_FORMAT=rgba32f"
  "flare.vert|main|"
  "flare.frag|main|"
)

set(gen ${CMAKE_CURRENT_BINARY_DIR}/spirv)
file(MAKE_DIRECTORY ${gen})
set(headers)
set(includes "")
set(entries "")
foreach(v IN LISTS GLINT_KERNEL_VARIANTS)
  string(REPLACE "|" ";" parts "${v}")
  list(GET parts 0 kernel)
  list(GET parts 1 variant)
  list(GET parts 2 defs)
  get_filename_component(stage "${kernel}" LAST_EXT)
  if(stage)
    get_filename_component(base "${kernel}" NAME_WLE)
    string(SUBSTRING "${stage}" 1 -1 stage)
    set(id "${base}_${stage}_${variant}")
    set(src ${CMAKE_CURRENT_SOURCE_DIR}/${kernel})
    set(specialized_check)
  else()
    set(id "${kernel}_${variant}")
    set(src ${CMAKE_CURRENT_SOURCE_DIR}/${kernel}.comp)
    set(specialized_check COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/check_specialized.sh ${SPIRV_OPT} ${SPIRV_VAL} ${gen}/${id}.spv)
  endif()
  string(REPLACE "+" ";" deflist "${defs}")
  set(dargs)
  foreach(d IN LISTS deflist)
    if(d)
      list(APPEND dargs "-D${d}")
    endif()
  endforeach()
  add_custom_command(
    OUTPUT ${gen}/${id}.h ${gen}/${id}.spv
    COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.3 -I${CMAKE_CURRENT_SOURCE_DIR}/common
            -I${PROJECT_SOURCE_DIR}/include ${dargs} -o ${gen}/${id}.spv ${src}
    COMMAND ${SPIRV_VAL} --target-env vulkan1.3 ${gen}/${id}.spv
    ${specialized_check}
    COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.3 -I${CMAKE_CURRENT_SOURCE_DIR}/common
            -I${PROJECT_SOURCE_DIR}/include ${dargs} --vn glint_spirv_${id} -o ${gen}/${id}.h ${src}
    DEPENDS ${src} ${GLINT_KERNEL_HEADERS} ${CMAKE_CURRENT_SOURCE_DIR}/check_specialized.sh
    COMMENT "glslang: ${id}"
    VERBATIM)
  list(APPEND headers ${gen}/${id}.h)
  string(APPEND includes "#include \"${id}.h\"\n")
  string(APPEND entries "    {\"${id}\", glint_spirv_${id}, sizeof(glint_spirv_${id})},\n")
endforeach()

configure_file(kernel_table.cpp.in ${gen}/kernel_table.cpp @ONLY)
add_library(glint_kernels STATIC ${gen}/kernel_table.cpp ${headers})
target_include_directories(glint_kernels PRIVATE ${gen} ${PROJECT_SOURCE_DIR}/host)
set_target_properties(glint_kernels PROPERTIES POSITION_INDEPENDENT_CODE ON)
