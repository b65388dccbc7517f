#pragma once

#include <algorithm>

namespace omnislam::vision {

/// Sub-pixel offset of a peak sampled at -1, 0, +1 (values a, b, c, b the largest): the
/// vertex of the parabola through them, clamped to half a pixel; 0 where they do not
/// curve down.
inline float parabola_vertex_offset(float a, float b, float c) {
  const float curvature = a - 2.0f * b + c;
  if (!(curvature < 0.0f)) return 0.0f;
  return std::clamp(0.5f * (a - c) / curvature, -0.5f, 0.5f);
}

}  // namespace omnislam::vision
