// The C++ twin of glint's GLSL LOD (include/glint/gpu/lod.glsl): the same source
// (include/glint/gpu/lod_impl.h) compiled as C++ in namespace glint::lod_math, so host code and
// tests compute exactly what the GPU kernels compute (up to the device's log2 and sqrt precision).
#pragma once

#include <glint/gpu/lod_impl.h>
