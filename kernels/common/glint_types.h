// Type names shared by GLSL and C++ so that a struct is declared once for both (STYLE rule 2).
// Only 4-byte scalars are used in shared structs, so the C++ and GLSL layouts agree trivially;
// the C++ side still static_asserts sizes and offsets.
#ifndef GLINT_TYPES_H
#define GLINT_TYPES_H
#ifdef __cplusplus
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
