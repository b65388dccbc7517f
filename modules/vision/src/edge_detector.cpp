#include "omnislam/vision/edge_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/imgproc.hpp>

#include "byte_mask.hpp"
#include "omnislam/vision/wide_vectors.hpp"

namespace omnislam::vision {
namespace {

// Sobel 3x3 on 8-bit input: |g| <= 4 * 255 * sqrt(2) < 1443.
constexpr int kMagnitudeBins = 1448;

// Pixel states of the padded edge map.
constexpr std::uint8_t kNotEdge = 0;
constexpr std::uint8_t kCandidate = 1;  // a local maximum between the thresholds
constexpr std::uint8_t kVisited = 128;  // an edge pixel already traced into its component
constexpr std::uint8_t kEdge = 255;
constexpr std::uint64_t kTopBits = 0x8080808080808080ull;

// tan(22.5 deg) in Q15: the gradient points within 22.5 deg of the column axis when
// |g_row| < tan(22.5) |g_col|, of the row axis when |g_row| > tan(67.5) |g_col|, and
// tan(67.5) = tan(22.5) + 2.
constexpr int kTan22Q15 = 13573;
constexpr int kQ15 = 1 << 15;
constexpr double kMaxThreshold = 32767.0;

}  // namespace

EdgeDetector::EdgeDetector(const CannyConfig &config) : config_(config) {
  const int half = config.half_window_px > 0
                       ? config.half_window_px
                       : std::max(1, static_cast<int>(std::ceil(3.0 * config.sigma_px)));
  kernel_size_ = cv::Size(2 * half + 1, 2 * half + 1);
}

void EdgeDetector::smooth_and_differentiate(const cv::Mat &panorama, EdgeImage &out) {
  if (config_.sigma_px > 0.0) {
    cv::GaussianBlur(panorama, smoothed_, kernel_size_, config_.sigma_px, config_.sigma_px,
                     cv::BORDER_REPLICATE);
  } else {
    panorama.copyTo(smoothed_);
  }
  cv::spatialGradient(smoothed_, out.grad_col, out.grad_row, 3, cv::BORDER_REPLICATE);  // Sobel 3x3
}

void EdgeDetector::detect(const cv::Mat &panorama, EdgeImage &out, std::span<const float> noise_floor) {
  smooth_and_differentiate(panorama, out);
  choose_thresholds(out, noise_floor);
  suppress_non_maxima(out);
  trace_edges(out);
}

std::vector<float> EdgeDetector::gradient_noise_per_row(const cv::Mat &panorama) {
  EdgeImage gradient;
  smooth_and_differentiate(panorama, gradient);
  const int rows = gradient.grad_row.rows, columns = gradient.grad_row.cols;
  constexpr int kHalfRows = 2;
  const float rayleigh_median = std::sqrt(2.0f * std::log(2.0f));
  std::vector<float> magnitudes;
  std::vector<float> scale(static_cast<std::size_t>(rows), 0.0f);
  for (int row = 0; row < rows; ++row) {
    magnitudes.clear();
    for (int r = std::max(0, row - kHalfRows); r <= std::min(rows - 1, row + kHalfRows); ++r) {
      const auto *gr = gradient.grad_row.ptr<std::int16_t>(r);
      const auto *gc = gradient.grad_col.ptr<std::int16_t>(r);
      for (int col = 0; col < columns; ++col)
        magnitudes.push_back(std::hypot(static_cast<float>(gr[col]), static_cast<float>(gc[col])));
    }
    const auto middle = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
    std::nth_element(magnitudes.begin(), middle, magnitudes.end());
    scale[static_cast<std::size_t>(row)] = *middle / rayleigh_median;
  }
  return scale;
}

OMNISLAM_WIDE_VECTORS void EdgeDetector::suppress_non_maxima(const EdgeImage &out) {
  // Canny on the L2 magnitude, as cv::Canny(dx, dy, ..., L2gradient = true) defines it, on
  // squared magnitudes in integers (the thresholds squared and floored: m > floor(t^2) is
  // sqrt(m) > t for an integer m). The magnitudes and the state map carry a border of one
  // zero pixel, so no neighbour needs a bounds check and the border never joins an edge.
  // Only three rows of magnitudes are alive at a time (above, here, below): a ring of three
  // padded rows stays in the first-level cache, where a whole padded image (330 KB a lobe)
  // went through memory.
  const int rows = out.grad_row.rows, columns = out.grad_row.cols;
  const auto padded = static_cast<std::size_t>(columns) + 2;
  magnitude_rows_.assign(3 * padded, 0);
  const auto fill = [&](int row, std::int32_t *line) {  // line[1 .. columns]; zero outside the image
    if (row < 0 || row >= rows) {
      std::fill_n(line + 1, columns, 0);
      return;
    }
    const auto *gr = out.grad_row.ptr<std::int16_t>(row);
    const auto *gc = out.grad_col.ptr<std::int16_t>(row);
    for (int col = 0; col < columns; ++col) line[col + 1] = gr[col] * gr[col] + gc[col] * gc[col];
  };
  std::int32_t *ring[3] = {magnitude_rows_.data(), magnitude_rows_.data() + padded,
                           magnitude_rows_.data() + 2 * padded};
  fill(-1, ring[0]);
  fill(0, ring[1]);
  state_.create(rows + 2, columns + 2, CV_8UC1);
  state_.setTo(kNotEdge);
  // Branch-free and without gathers, so that the compiler vectorises it: about half the
  // pixels of a textured floor pass the low threshold, at random, and a branch per test
  // would be mispredicted that often. Every direction's test is computed, one is kept.
  // Each pixel enters the trace at most once: one slot per pixel, allocated once per size.
  trace_.resize(static_cast<std::size_t>(rows) * static_cast<std::size_t>(columns));
  std::size_t strong = 0;
  const std::uint8_t *origin = state_.ptr<std::uint8_t>(0);
  for (int row = 0; row < rows; ++row) {
    fill(row + 1, ring[2]);
    const auto *gr = out.grad_row.ptr<std::int16_t>(row);
    const auto *gc = out.grad_col.ptr<std::int16_t>(row);
    const std::int32_t *above = ring[0] + 1;
    const std::int32_t *m = ring[1] + 1;
    const std::int32_t *below = ring[2] + 1;
    std::uint8_t *state = state_.ptr<std::uint8_t>(row + 1) + 1;
    const std::int32_t low = row_low_sq_[static_cast<std::size_t>(row)];
    const std::int32_t high = row_high_sq_[static_cast<std::size_t>(row)];
    for (int col = 0; col < columns; ++col) {
      const int across = std::abs(static_cast<int>(gc[col])), along = std::abs(static_cast<int>(gr[col]));
      const int tan22 = across * kTan22Q15, scaled = along * kQ15;
      const int along_row = static_cast<int>(scaled < tan22);
      const int along_column = static_cast<int>(scaled > tan22 + 2 * across * kQ15);
      const int same_signs = static_cast<int>((gr[col] < 0) == (gc[col] < 0));
      // The local maximum against the two neighbours along the gradient. On a plateau along
      // a row or a column its first pixel survives, along a diagonal none does (cv::Canny's
      // rule, kept so that the edges are the same).
      const std::int32_t here = m[col];
      const int row_max = static_cast<int>(here > m[col - 1]) & static_cast<int>(here >= m[col + 1]);
      const int column_max = static_cast<int>(here > above[col]) & static_cast<int>(here >= below[col]);
      const int falling_max =
          static_cast<int>(here > above[col - 1]) & static_cast<int>(here > below[col + 1]);
      const int rising_max =
          static_cast<int>(here > above[col + 1]) & static_cast<int>(here > below[col - 1]);
      const int diagonal_max = same_signs != 0 ? falling_max : rising_max;
      const int direction_max = along_row != 0 ? row_max : along_column != 0 ? column_max : diagonal_max;
      const int maximum = static_cast<int>(here > low) & direction_max;
      const int edge = maximum & static_cast<int>(here > high);
      state[col] = static_cast<std::uint8_t>(maximum * kCandidate + edge * (kEdge - kCandidate));
    }
    // Few pixels pass the high threshold: find them eight at a time (only kEdge has the
    // top bit of its byte set) instead of storing a slot for every pixel.
    const std::ptrdiff_t first = state - origin;
    int col = 0;
    for (; col + 8 <= columns; col += 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, state + col, sizeof word);
      for (word &= kTopBits; word != 0; word &= word - 1)
        trace_[strong++] = first + col + byte_of_lowest_bit(word);
    }
    for (; col < columns; ++col) {
      if (state[col] == kEdge) trace_[strong++] = first + col;
    }
    std::rotate(std::begin(ring), std::begin(ring) + 1, std::end(ring));
  }
  trace_top_ = strong;
}

void EdgeDetector::trace_edges(EdgeImage &out) {
  // Hysteresis and fragment removal in one pass over the strong pixels: the 8-connected
  // components of the final edge map are exactly the components of (candidates + strong
  // pixels) that hold a strong pixel, so each one is traced from its first strong pixel,
  // counted, and dropped whole when it is a fragment. Pixels of components kept become
  // kVisited; those of fragments, and candidates no strong pixel reaches, end as not edges.
  std::uint8_t *data = state_.ptr<std::uint8_t>(0);
  const auto step = static_cast<std::ptrdiff_t>(state_.step);
  const std::array<std::ptrdiff_t, 8> neighbours{-step - 1, -step,    -step + 1, -1,
                                                 1,         step - 1, step,      step + 1};
  const auto min_size = static_cast<std::size_t>(std::max(1, config_.min_fragment_px));
  // A component is at most the whole image: one slot per pixel (and one for the slot a
  // neighbour is written to before it is known to join), allocated once per size.
  component_.resize(trace_.size() + 1);
  std::ptrdiff_t *component = component_.data();
  out.canny_px = 0;
  out.fragment_px_removed = 0;
  for (std::size_t seed = 0; seed < trace_top_; ++seed) {
    const std::ptrdiff_t start = trace_[seed];
    if (data[start] != kEdge) continue;  // in a component traced from an earlier seed
    data[start] = kVisited;
    component[0] = start;
    std::size_t size = 1;
    for (std::size_t next = 0; next < size; ++next) {
      const std::ptrdiff_t index = component[next];
      // Half the pixels of a textured floor are candidates, at random: each neighbour is
      // appended (and marked) without a branch, its slot kept only when it joins.
      for (const std::ptrdiff_t offset : neighbours) {
        std::uint8_t &pixel = data[index + offset];
        const bool joins = (pixel == kCandidate) | (pixel == kEdge);
        component[size] = index + offset;
        size += static_cast<std::size_t>(joins);
        pixel = joins ? kVisited : pixel;
      }
    }
    out.canny_px += static_cast<int>(size);
    if (size < min_size) {
      for (std::size_t i = 0; i < size; ++i) data[component[i]] = kNotEdge;
      out.fragment_px_removed += static_cast<int>(size);
    }
  }
  trace_top_ = 0;
  const cv::Rect interior(1, 1, out.grad_row.cols, out.grad_row.rows);
  cv::compare(state_(interior), kVisited, out.edges, cv::CMP_EQ);
}

void EdgeDetector::choose_thresholds(EdgeImage &out, std::span<const float> noise_floor) {
  if (config_.auto_thresholds) {
    choose_auto_thresholds(out);
  } else {
    out.high_threshold = config_.high_threshold;
    out.low_threshold = config_.low_threshold;
  }
  // Each row's high threshold is at least what the frame's noise reaches there (automatic
  // thresholds only), its low one following at auto_low_ratio. Thresholds beyond any
  // magnitude are capped (as cv::Canny does) so that squares fit.
  const auto squared = [](double threshold) {
    const double capped = std::min(threshold, kMaxThreshold);
    return static_cast<std::int32_t>(std::floor(capped * capped));
  };
  const auto rows = static_cast<std::size_t>(out.grad_row.rows);
  const bool floored = config_.auto_thresholds && noise_floor.size() == rows;
  out.noise_high_threshold = 0.0;
  row_low_sq_.resize(rows);
  row_high_sq_.resize(rows);
  for (std::size_t row = 0; row < rows; ++row) {
    const double floor = floored ? static_cast<double>(noise_floor[row]) : 0.0;
    const bool raised = floor > out.high_threshold;
    if (raised) out.noise_high_threshold = std::max(out.noise_high_threshold, floor);
    row_high_sq_[row] = squared(raised ? floor : out.high_threshold);
    row_low_sq_[row] = squared(raised ? config_.auto_low_ratio * floor : out.low_threshold);
  }
}

void EdgeDetector::choose_auto_thresholds(EdgeImage &out) {
  // Quantile of the L2 gradient magnitude via an integer histogram of every other pixel
  // of every other row (a quarter of the pixels estimates a quantile to well under 1%).
  std::array<int, kMagnitudeBins> histogram{};
  int sampled = 0;
  for (int row = 0; row < out.grad_row.rows; row += 2) {
    const auto *gr = out.grad_row.ptr<std::int16_t>(row);
    const auto *gc = out.grad_col.ptr<std::int16_t>(row);
    for (int col = 0; col < out.grad_row.cols; col += 2, ++sampled) {
      const int squared = gr[col] * gr[col] + gc[col] * gc[col];
      const int bin = static_cast<int>(std::sqrt(static_cast<float>(squared)));
      ++histogram[static_cast<std::size_t>(std::min(bin, kMagnitudeBins - 1))];
    }
  }
  const double wanted = config_.auto_not_edge_fraction * sampled;
  double cumulative = 0.0;
  int quantile = kMagnitudeBins - 1;
  for (int bin = 0; bin < kMagnitudeBins; ++bin) {
    cumulative += histogram[static_cast<std::size_t>(bin)];
    if (cumulative >= wanted) {
      quantile = bin + 1;
      break;
    }
  }
  out.high_threshold = std::max(static_cast<double>(quantile), config_.auto_min_high_threshold);
  out.low_threshold = config_.auto_low_ratio * out.high_threshold;
}

}  // namespace omnislam::vision
