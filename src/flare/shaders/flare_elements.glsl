// The flare elements as functions of the tile's normalized coordinate q in (-1, 1)^2 (texel centre
// (i + 0.5) / w * 2 - 1), premultiplied RGBA. Shapes (docs/FLARE.md, "Elements"): Gaussian/exponential glow, a wide horizontal streak with a tight vertical profile and
// a central bulge, a soft ring with a slight chromatic spread, radial spikes, and a hexagonal
// aperture ghost with a brighter rim. Every element is multiplied by a window that is 0 at the
// tile border, so the padding (zeros) is each tile's own edge value. Only exp, smoothstep, sqrt and
// products are used (no atan, no pow: Vulkan allows atan 4096 ulp, which would move thin spikes);
// tools/reference/flare_reference.cpp evaluates the same formulas in float64.
#include "glint/gpu/flare_types.h"

float glint_flare_window(float r) {  // (1 - r^2)^2 inside the unit disc, 0 outside
  float t = max(1.0 - r * r, 0.0);
  return t * t;
}

float glint_flare_gauss(float x, float sigma) { return exp(-(x * x) / (2.0 * sigma * sigma)); }

vec4 glint_flare_element(uint element, vec2 q) {
  float r = sqrt(q.x * q.x + q.y * q.y);
  if (element == GLINT_FLARE_ELEMENT_GLOW) {
    float g = exp(-8.0 * r * r) * glint_flare_window(r);
    return vec4(g, g, g, g);
  }
  if (element == GLINT_FLARE_ELEMENT_STREAK) {
    float wide = glint_flare_gauss(q.x, 0.35) * glint_flare_gauss(q.y, 0.22);
    float bulge = glint_flare_gauss(q.x, 0.08) * glint_flare_gauss(q.y, 0.3);
    float g = (wide + 0.6 * bulge) / 1.6 * glint_flare_window(abs(q.x)) * glint_flare_window(abs(q.y));
    return vec4(g, g, g, g);
  }
  if (element == GLINT_FLARE_ELEMENT_HALO) {
    float w = 0.8 * glint_flare_window(r);
    vec3 rgb = w * vec3(exp(-((r - 0.74) / 0.06) * ((r - 0.74) / 0.06)), exp(-((r - 0.70) / 0.06) * ((r - 0.70) / 0.06)),
                        exp(-((r - 0.66) / 0.06) * ((r - 0.66) / 0.06)));
    return vec4(rgb, max(rgb.r, max(rgb.g, rgb.b)));
  }
  if (element == GLINT_FLARE_ELEMENT_STARBURST) {
    float c = r > 0.0 ? q.x / r : 1.0;
    float t3 = 4.0 * c * c * c - 3.0 * c;  // cos(3 theta), Chebyshev T3: six spikes
    float s = t3 * t3;
    float s2 = s * s, s4 = s2 * s2, s8 = s4 * s4, s16 = s8 * s8;
    float n = 1.0 - s;  // sin^2(3 theta): six fainter spikes in between
    float n2 = n * n, n4 = n2 * n2, n8 = n4 * n4, n16 = n8 * n8;
    float g = glint_flare_window(r) * (0.8 * s16 * s8 * exp(-3.0 * r) + 0.35 * n16 * n8 * exp(-5.0 * r) + exp(-40.0 * r * r));
    return vec4(g, g, g, min(g, 1.0));
  }
  // GLINT_FLARE_ELEMENT_GHOST: hexagon (flat top and bottom), slightly larger in red than in blue.
  float h = max(abs(q.y), abs(q.x) * 0.8660254 + abs(q.y) * 0.5);
  vec3 hh = vec3(h * 0.97, h, h * 1.03);
  vec3 body = vec3(1.0) - smoothstep(vec3(0.62), vec3(0.72), hh);
  vec3 rim = exp(-((hh - 0.68) / 0.05) * ((hh - 0.68) / 0.05));
  vec3 rgb = (0.35 * body + 0.5 * rim) * glint_flare_window(r);
  return vec4(rgb, max(rgb.r, max(rgb.g, rgb.b)));
}
