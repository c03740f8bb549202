# glint_add_kernels(<target> NAMESPACE <ns> VARIANTS <variant>...): compiles kernels to SPIR-V for
# Vulkan 1.3 at build time, checks each with spirv-val and embeds them in the static library
# <target> as uint32_t arrays, with a lookup `const KernelBinary* <ns>::find_kernel(const char* id)`
# (src/core/kernel_table.h). Called once for the library's kernels (src/CMakeLists.txt, namespace
# glint::detail) and once for the tools' (tools/CMakeLists.txt, the demo scene's kernel).
#
# One entry per variant: PATH|VARIANT|DEFINES (defines separated by '+'). PATH is the kernel's path
# without ".comp" for a compute kernel, which gets the id <name>_<variant> (bloom_down_rgba16f); a
# graphics stage is listed with its file name (flare.vert, flare.frag) and gets the id
# <name>_<stage>_<variant> (flare_vert_main). Only compute kernels take the specialization check
# (check_specialized.sh): the graphics stages have no workgroup constants.
#
# Kernels that write an image are compiled once per storage format (rgba16f, rgba32f), since
# lavapipe lacks shaderStorageImageReadWithoutFormat. Kernels that write the caller's output (bloom
# composite, image copy, the blur kernels) also get r11f_g11f_b10f (VK_FORMAT_B10G11R11_UFLOAT_PACK32)
# and noformat: no qualifier, for the other float colour formats whose format features include
# STORAGE_WRITE_WITHOUT_FORMAT (src/core/shaders/dst_image.glsl, src/core/formats.h).
#
# A kernel includes the headers of its own folder by name (glslang looks beside the including file
# first), the shared GLSL of src/core/shaders by name, and the installed GLSL/C++ shared headers as
# "glint/gpu/..." from include/ (the same files engines get). A kernel is recompiled when any .glsl
# or .h of its own folder, src/core/shaders or include/glint/gpu changes.
function(glint_add_kernels target)
  set(table_in ${PROJECT_SOURCE_DIR}/src/core/kernel_table.cpp.in)
  set(check_specialized ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/check_specialized.sh)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "NAMESPACE" "VARIANTS")
  set(gen ${CMAKE_CURRENT_BINARY_DIR}/${target}_spirv)
  file(MAKE_DIRECTORY ${gen})
  set(core_shaders ${PROJECT_SOURCE_DIR}/src/core/shaders)
  file(GLOB shared_headers CONFIGURE_DEPENDS ${core_shaders}/* ${PROJECT_SOURCE_DIR}/include/glint/gpu/*)
  set(headers)
  set(includes "")
  set(entries "")
  foreach(v IN LISTS arg_VARIANTS)
    string(REPLACE "|" ";" parts "${v}")
    list(GET parts 0 kernel)
    list(GET parts 1 variant)
    list(GET parts 2 defs)
    get_filename_component(dir "${kernel}" DIRECTORY)
    get_filename_component(stage "${kernel}" LAST_EXT)
    if(stage)
      get_filename_component(base "${kernel}" NAME_WLE)
      string(SUBSTRING "${stage}" 1 -1 stage)
      set(id "${base}_${stage}_${variant}")
      set(src ${kernel})
      set(specialized_check)
    else()
      get_filename_component(base "${kernel}" NAME)
      set(id "${base}_${variant}")
      set(src ${kernel}.comp)
      set(specialized_check COMMAND ${check_specialized} ${SPIRV_OPT} ${SPIRV_VAL} ${gen}/${id}.spv)
    endif()
    file(GLOB own_headers CONFIGURE_DEPENDS ${dir}/*.glsl ${dir}/*.h)
    string(REPLACE "+" ";" deflist "${defs}")
    set(dargs)
    foreach(d IN LISTS deflist)
      if(d)
        list(APPEND dargs "-D${d}")
      endif()
    endforeach()
    add_custom_command(
      OUTPUT ${gen}/${id}.h ${gen}/${id}.spv
      COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.3 -I${core_shaders}
              -I${PROJECT_SOURCE_DIR}/include ${dargs} -o ${gen}/${id}.spv ${src}
      COMMAND ${SPIRV_VAL} --target-env vulkan1.3 ${gen}/${id}.spv
      ${specialized_check}
      COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.3 -I${core_shaders}
              -I${PROJECT_SOURCE_DIR}/include ${dargs} --vn glint_spirv_${id} -o ${gen}/${id}.h ${src}
      DEPENDS ${src} ${own_headers} ${shared_headers} ${check_specialized}
      COMMENT "glslang: ${id}"
      VERBATIM)
    list(APPEND headers ${gen}/${id}.h)
    string(APPEND includes "#include \"${id}.h\"\n")
    string(APPEND entries "    {\"${id}\", glint_spirv_${id}, sizeof(glint_spirv_${id})},\n")
  endforeach()

  set(GLINT_KERNEL_INCLUDES "${includes}")
  set(GLINT_KERNEL_ENTRIES "${entries}")
  set(GLINT_KERNEL_NAMESPACE "${arg_NAMESPACE}")
  configure_file(${table_in} ${gen}/kernel_table.cpp @ONLY)
  add_library(${target} STATIC ${gen}/kernel_table.cpp ${headers})
  target_include_directories(${target} PRIVATE ${gen} ${PROJECT_SOURCE_DIR}/src)
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
