// Push constants of tools/demo/shaders/demo_starfield.comp, shared with tools/demo/demo_scene.cpp.
#ifndef GLINT_DEMO_PARAMS_H
#define GLINT_DEMO_PARAMS_H
#include "glint/gpu/types.h"

struct StarfieldPush {
  GLINT_INT width;
  GLINT_INT height;
  GLINT_INT cell_px;          // one candidate star per cell of cell_px x cell_px pixels
  GLINT_UINT variant;         // which starfield: mixed into the per-cell hash
  GLINT_FLOAT min_brightness; // star brightness range (log-uniform)
  GLINT_FLOAT max_brightness;
  GLINT_FLOAT sun_brightness;
  GLINT_FLOAT sun_radius_px;
  GLINT_FLOAT sun_x;          // sun centre in pixels
  GLINT_FLOAT sun_y;
  GLINT_FLOAT star_probability;  // chance a cell holds a star
  GLINT_UINT reserved;
};

#endif
