#include "analysis/light_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace glint::analysis {

CpuImage subpixel_point(uint32_t width, uint32_t height, double x, double y, float value, float background) {
  CpuImage img(width, height, background);
  for (uint32_t j = 0; j < height; ++j)
    for (uint32_t i = 0; i < width; ++i) img.at(i, j)[3] = 1.0f;
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const double fx = x - fx0, fy = y - fy0;
  const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
  const double weights[2][2] = {{(1 - fx) * (1 - fy), fx * (1 - fy)}, {(1 - fx) * fy, fx * fy}};
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const double w = weights[dj][di];
      if (w == 0.0) continue;  // also keeps (w-1, h-1) inside the image
      float* p = img.at(uint32_t(i0 + di), uint32_t(j0 + dj));
      for (int c = 0; c < 3; ++c) p[c] += static_cast<float>(value * w);
    }
  return img;
}

std::vector<double> added_light(const CpuImage& out, const CpuImage& in) {
  std::vector<double> added(size_t(in.width) * in.height);
  for (size_t i = 0; i < added.size(); ++i) {
    double s = 0.0;
    for (int c = 0; c < 3; ++c) s += double(out.rgba[i * 4 + c]) - double(in.rgba[i * 4 + c]);
    added[i] = s;
  }
  return added;
}

LightStats light_stats(const std::vector<double>& added, uint32_t width, uint32_t height) {
  LightStats s;
  double sx = 0, sy = 0;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const double a = added[size_t(y) * width + x];
      s.energy += a;
      sx += a * x;
      sy += a * y;
    }
  if (s.energy == 0.0) return s;
  s.cx = sx / s.energy;
  s.cy = sy / s.energy;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const double a = added[size_t(y) * width + x];
      s.xx += a * (x - s.cx) * (x - s.cx);
      s.yy += a * (y - s.cy) * (y - s.cy);
    }
  s.xx /= s.energy;
  s.yy /= s.energy;
  return s;
}

double radius_holding(const std::vector<double>& added, uint32_t width, uint32_t height, double cx, double cy,
                      double fraction) {
  std::vector<std::pair<double, double>> by_distance;  // (distance, light)
  by_distance.reserve(added.size());
  double total = 0.0;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const double a = std::max(0.0, added[size_t(y) * width + x]);
      if (a == 0.0) continue;
      by_distance.emplace_back(std::hypot(x - cx, y - cy), a);
      total += a;
    }
  std::sort(by_distance.begin(), by_distance.end());
  double sum = 0.0;
  for (const auto& [d, a] : by_distance) {
    sum += a;
    if (sum >= fraction * total) return d;
  }
  return by_distance.empty() ? 0.0 : by_distance.back().first;
}

Variation relative_variation(const std::vector<double>& series) {
  Variation v;
  if (series.empty()) return v;
  const double mean = std::accumulate(series.begin(), series.end(), 0.0) / double(series.size());
  const auto [lo, hi] = std::minmax_element(series.begin(), series.end());
  v.spread = (*hi - *lo) / mean;
  for (size_t i = 1; i < series.size(); ++i)
    v.max_step = std::max(v.max_step, std::fabs(series[i] - series[i - 1]) / mean);
  return v;
}

}  // namespace glint::analysis
