// Scalar type names shared by GLSL and C++, so that every struct glint's buffers hold is declared
// once for both. Installed: engines include <glint/gpu/...> from C++ and "glint/gpu/..." from GLSL
// (glslangValidator -I<prefix>/include, with GL_GOOGLE_include_directive).
// Shared structs use only 4-byte scalars, so the C++ layout equals GLSL's std430 layout member for
// member; each header static_asserts its sizes and offsets on the C++ side.
#ifndef GLINT_GPU_TYPES_H
#define GLINT_GPU_TYPES_H
#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#define GLINT_UINT uint32_t
#define GLINT_INT int32_t
#define GLINT_FLOAT float
#else
#define GLINT_UINT uint
#define GLINT_INT int
#define GLINT_FLOAT float
#endif
#endif
