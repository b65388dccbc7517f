#include "omnislam/vision/ray_subpixel.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "parabola.hpp"

namespace omnislam::vision {
namespace {

// A normalised 1-D Gaussian of `sigma_px` (3 sigma each side, at most kMaxHalfTaps), on
// the stack: no allocation per call.
constexpr int kMaxHalfTaps = 15;  // sigma up to 5 px, the configuration's limit
struct Taps {
  std::array<float, 2 * kMaxHalfTaps + 1> weight{};
  int half = 0;
};
Taps gaussian_taps(double sigma_px) {
  Taps taps;
  taps.half = std::min(kMaxHalfTaps, static_cast<int>(std::ceil(3.0 * sigma_px)));
  double sum = 0.0;
  for (int i = -taps.half; i <= taps.half; ++i) sum += std::exp(-0.5 * i * i / (sigma_px * sigma_px));
  for (int i = -taps.half; i <= taps.half; ++i)
    taps.weight[static_cast<std::size_t>(i + taps.half)] =
        static_cast<float>(std::exp(-0.5 * i * i / (sigma_px * sigma_px)) / sum);
  return taps;
}

// One column's profile about `row`: the texture smoothed along the column by `taps`, S,
// and its central differences S(r + 1) - S(r - 1) at rows row - 2 .. row + 2.
class RayProfile {
 public:
  RayProfile(const cv::Mat &texture, int row, int column, const Taps &taps) : row_(row) {
    const int half = taps.half;
    const int last = texture.rows - 1;
    std::array<float, 7> smoothed{};
    for (int i = 0; i < 7; ++i) {
      float sum = 0.0f;
      for (int t = -half; t <= half; ++t)
        sum += taps.weight[static_cast<std::size_t>(t + half)] *
               texture.at<float>(std::clamp(row - 3 + i + t, 0, last), column);
      smoothed[static_cast<std::size_t>(i)] = sum;
    }
    for (int i = 0; i < 5; ++i)
      difference_[static_cast<std::size_t>(i)] =
          smoothed[static_cast<std::size_t>(i + 2)] - smoothed[static_cast<std::size_t>(i)];
  }

  [[nodiscard]] float polarity() const { return difference_[2] >= 0.0f ? 1.0f : -1.0f; }

  // The peak of the gradient of polarity `sign` among row - 1 .. row + 1, refined by a
  // parabola; empty when none of those rows is a local maximum of it.
  [[nodiscard]] std::optional<float> peak(float sign) const {
    std::array<float, 5> g{};
    for (std::size_t i = 0; i < 5; ++i) g[i] = std::max(0.0f, sign * difference_[i]);
    std::size_t best = 2;
    if (g[1] > g[best]) best = 1;
    if (g[3] > g[best]) best = 3;
    if (!(g[best] > 0.0f) || g[best - 1] > g[best] || g[best + 1] > g[best]) return std::nullopt;
    return static_cast<float>(row_ + static_cast<int>(best) - 2) +
           parabola_vertex_offset(g[best - 1], g[best], g[best + 1]);
  }

 private:
  int row_;
  std::array<float, 5> difference_{};
};

}  // namespace

float ray_subpixel_row(const cv::Mat &texture, const EdgeImage &edges, const EdgePoint &edge, int column,
                       double sigma_px) {
  if (!(sigma_px > 0.0)) return edge.row_subpx;
  const Taps taps = gaussian_taps(sigma_px);
  const RayProfile own_profile(texture, edge.row, column, taps);
  const float sign = own_profile.polarity();
  const std::optional<float> own = own_profile.peak(sign);
  if (!own) return edge.row_subpx;
  // Rows per column along the edge: its tangent is across Canny's gradient.
  const float along = edges.grad_row.at<std::int16_t>(edge.row, column);
  const float across = edges.grad_col.at<std::int16_t>(edge.row, column);
  const float slope = along != 0.0f ? -across / along : 0.0f;
  float sum = *own;
  for (const int side : {-1, 1}) {
    const int neighbour = (column + side + texture.cols) % texture.cols;
    const float predicted = *own + static_cast<float>(side) * slope;
    const int near = static_cast<int>(std::lround(predicted));
    if (near < 1 || near > texture.rows - 2) return *own;
    const std::optional<float> found = RayProfile(texture, near, neighbour, taps).peak(sign);
    if (!found || std::abs(*found - predicted) > 1.0f) return *own;
    // A line through the three rows, read at the middle column: their mean.
    sum += *found - static_cast<float>(side) * slope;
  }
  return sum / 3.0f;
}

}  // namespace omnislam::vision
