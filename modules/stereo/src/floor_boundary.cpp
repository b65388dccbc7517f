#include "omnislam/stereo/floor_boundary.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "omnislam/vision/ray_subpixel.hpp"
#include "omnislam/vision/wide_vectors.hpp"

namespace omnislam::stereo {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// 8-bit images cannot resolve less than one grey level.
constexpr float kMinNoiseScale = 1.0f / 255.0f;
// Below this the ratio of two intensities says nothing (the black surround, deep shadow).
constexpr float kDarkLevel = 0.02f;
// Image radii enter the lobes' gain model in units of the thesis image radius.
constexpr float kRadiusUnitPx = 512.0f;
// Each row's vote is capped (an occlusion edge or a highlight is one bad row, not proof)
// and halved: the residuals of neighbouring rows share the 5x5 smoothing.
constexpr float kMaxRowVote = 3.0f;
constexpr float kRowCorrelation = 0.5f;
constexpr float kDeadZone = 2.0f;  // in units of the residual scale
// Beyond the dead zone and the cap, a residual is larger than a row's vote can explain.
constexpr float kOutlierResidual = kDeadZone + kMaxRowVote;
// The 7 x 3 similarity window's pixels share the smoothing in both directions.
constexpr float kWindowCorrelation = 0.25f;
// An edge spreads over +-3 rows after the detector's and the residual's smoothing.
constexpr int kEdgeBlurRows = 3;
// An edge's outer twin on the floor is sought this far from the floor's row when the frame's
// sub-pixel placement error is measured (several times any spread seen).
constexpr float kTwinSearchRows = 2.5f;
// Drops: a rim seen one degree further round moves by a few percent at the angles the camera
// sees it; a rim runs on across at least this many columns (a floor edge whose own twin was
// missed, 30-70 a frame in any room, makes runs of 2-3 columns, rarely more).
constexpr float kDropAlike = 0.1f;
constexpr int kDropRimColumns = 4;

// Whether a drop at `other_m` goes on from one at `range_m` (kDropAlike of range_m).
bool drops_alike(float range_m, float other_m) { return std::abs(range_m - other_m) <= kDropAlike * range_m; }

int polarity(const vision::EdgeImage &edges, int row, int column) {
  return edges.grad_row.at<std::int16_t>(row, column) >= 0 ? 1 : -1;
}

// How many rows an edge moves per column along itself: its gradient's normal in the panorama
// (the stereo match on a misaligned rig follows it to the epipolar curve; row_triangulator.hpp).
float rows_per_column(const vision::EdgeImage &edges, const vision::EdgePoint &edge, int column) {
  const auto along = static_cast<float>(edges.grad_row.at<std::int16_t>(edge.row, column));
  const auto across = static_cast<float>(edges.grad_col.at<std::int16_t>(edge.row, column));
  return along != 0.0f ? -across / along : 0.0f;
}

// interpolate()'s arithmetic for a whole panorama row: the two rows around `row` of a lobe
// with `rows` rows and the fraction between them.
struct RowBlend {
  int below = 0;
  float fraction = 0.0f;
};
RowBlend row_blend(float row, int rows) {
  const float clamped = std::clamp(row, 0.0f, static_cast<float>(rows - 1));
  const int below = std::min(rows - 2, static_cast<int>(clamped));
  return {below, clamped - static_cast<float>(below)};
}

// Below this many values nth_element is cheaper than clearing the radix histograms.
constexpr std::size_t kRadixSelectMin = 2048;

// The element nth_element would put in the middle. Large samples of non-negative values (the
// frame's ~10,000 floor residuals) are selected by radix on their IEEE bits, which order as
// unsigned integers: three branch-free histogram passes (11, 11 and 10 bits) instead of a
// partition whose comparisons of random data mispredict half the time.
float median_of(std::vector<float> &values) {
  if (values.empty()) return kNaN;
  std::size_t rank = values.size() / 2;
  const auto nth = [&] {
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(rank);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  };
  if (values.size() < kRadixSelectMin) return nth();
  std::array<std::uint32_t, 2048> histogram{};
  std::uint32_t prefix = 0, prefix_mask = 0;
  for (const int shift : {21, 10, 0}) {
    const std::uint32_t digits = shift == 0 ? 0x3ffu : 0x7ffu;
    histogram.fill(0);
    std::uint32_t signs = 0;
    for (const float value : values) {
      const auto bits = std::bit_cast<std::uint32_t>(value);
      signs |= bits;
      histogram[(bits >> shift) & digits] += static_cast<std::uint32_t>((bits & prefix_mask) == prefix);
    }
    // A negative value (or -0) has its sign bit set and the bits do not order it (every pass
    // sees every value, so the first one decides; OR-ing in the pass costs less than a pass).
    if (signs >> 31 != 0) return nth();
    std::uint32_t digit = 0;
    while (rank >= histogram[digit]) rank -= histogram[digit++];
    prefix |= digit << shift;
    prefix_mask |= digits << shift;
  }
  return std::bit_cast<float>(prefix);
}

}  // namespace

float FloorBoundaryFinder::radius_term(int inner_row, float outer_row) const {
  const float outer = geometry_->outer_radius_px(outer_row) / kRadiusUnitPx;
  return outer * outer - inner_radius_squared_[static_cast<std::size_t>(inner_row)];
}

float FloorBoundaryFinder::gain(int inner_row, float outer_row) const {
  return gain_at_centre_ + gain_slope_ * radius_term(inner_row, outer_row);
}

FloorBoundaryFinder::FloorBoundaryFinder(const FloorBoundaryConfig &config)
    : config_(config), decision_llr_(std::log((1.0 - config.error_rate) / config.error_rate)) {}

float FloorBoundaryFinder::interpolate(const float *line, float row) const {
  const auto [below, fraction] = row_blend(row, rows_);
  return line[below] + fraction * (line[below + 1] - line[below]);
}

float FloorBoundaryFinder::outer_at(float row, int column) const {
  return interpolate(outer_.ptr<float>(column), row);
}

void FloorBoundaryFinder::prepare(const cv::Mat &inner_texture, const cv::Mat &outer_texture) {
  // Smoothed, then stored column by column: every later loop walks one column's rows.
  cv::GaussianBlur(inner_texture, smoothed_inner_, cv::Size(5, 5), 1.0, 1.0, cv::BORDER_REPLICATE);
  cv::transpose(smoothed_inner_, inner_);
  cv::GaussianBlur(outer_texture, smoothed_outer_, cv::Size(5, 5), 1.0, 1.0, cv::BORDER_REPLICATE);
  cv::transpose(smoothed_outer_, outer_);
  rows_ = inner_texture.rows;
  const int rows = rows_, columns = inner_texture.cols;
  inner_radius_squared_.resize(static_cast<std::size_t>(rows));
  for (int row = 0; row < rows; ++row) {
    const float radius = geometry_->inner_radius_px(static_cast<float>(row)) / kRadiusUnitPx;
    inner_radius_squared_[static_cast<std::size_t>(row)] = radius * radius;
  }
  fit_lobe_gain();
  floor_gain_.resize(static_cast<std::size_t>(rows));
  for (int row = 0; row < rows; ++row) {
    const float outer_row = geometry_->floor_outer_row(row);
    floor_gain_[static_cast<std::size_t>(row)] = std::isfinite(outer_row) ? gain(row, outer_row) : kNaN;
  }
  // The floor's outer row is the same in every column, so the residual is computed a whole
  // panorama row at a time (contiguous, vectorised) and then transposed like the textures.
  floor_residual_rows_.create(rows, columns, CV_32FC1);
  for (int row = 0; row < rows; ++row) {
    float *residual = floor_residual_rows_.ptr<float>(row);
    const float g = floor_gain_[static_cast<std::size_t>(row)];
    if (!std::isfinite(g)) {
      std::fill_n(residual, columns, kNaN);
      continue;
    }
    const auto [below, fraction] = row_blend(geometry_->floor_outer_row(row), rows);
    const float *inner = smoothed_inner_.ptr<float>(row);
    const float *low = smoothed_outer_.ptr<float>(below), *high = smoothed_outer_.ptr<float>(below + 1);
    for (int column = 0; column < columns; ++column)
      residual[column] =
          std::abs(inner[column] - g * (low[column] + fraction * (high[column] - low[column])));
  }
  cv::transpose(floor_residual_rows_, floor_residual_);
  measure_noise_scale();
}

void FloorBoundaryFinder::fit_lobe_gain() {
  const int rows = rows_, columns = smoothed_inner_.cols;
  // The lobes differ in brightness by the mirror's reflectance and the lens's radial
  // falloff (vignetting), both functions of the image radius. Fit the first-order model of
  // gain() to the median brightness ratio of each row nearest the robot, where nearly
  // every column sees floor and the floor hypothesis pairs the same point; rows higher up
  // see walls, where that pairing is what is being tested and would bias the fit.
  // Every other row and column: two parameters from ~50 medians of ~180 ratios each.
  double sxx = 0.0, sx = 0.0, sy = 0.0, sxy = 0.0, n = 0.0;
  for (int row = rows / 2; row < rows; row += 2) {
    const float outer_row = geometry_->floor_outer_row(row);
    if (!std::isfinite(outer_row)) continue;
    ratios_.clear();
    const auto [below, fraction] = row_blend(outer_row, rows);
    const float *inner_line = smoothed_inner_.ptr<float>(row);
    const float *low = smoothed_outer_.ptr<float>(below), *high = smoothed_outer_.ptr<float>(below + 1);
    for (int column = 0; column < columns; column += 2) {
      const float inner = inner_line[column];
      const float outer = low[column] + fraction * (high[column] - low[column]);
      if (inner > kDarkLevel && outer > kDarkLevel) ratios_.push_back(inner / outer);
    }
    if (ratios_.size() * 4 < static_cast<std::size_t>(columns)) continue;
    const double x = radius_term(row, outer_row), y = median_of(ratios_);
    sxx += x * x, sx += x, sy += y, sxy += x * y, n += 1.0;
  }
  const double determinant = n * sxx - sx * sx;
  gain_at_centre_ = 1.0f, gain_slope_ = 0.0f;
  if (n >= 8.0 && determinant > 1e-12) {
    gain_slope_ = static_cast<float>((n * sxy - sx * sy) / determinant);
    gain_at_centre_ = static_cast<float>((sy - gain_slope_ * sx) / n);
  } else if (n >= 1.0) {
    gain_at_centre_ = static_cast<float>(sy / n);
  }
}

void FloorBoundaryFinder::measure_noise_scale() {
  const int rows = rows_, columns = floor_residual_rows_.cols;
  // From the rows nearest the robot, mostly floor in any room: a Laplace distribution's
  // scale is its median absolute value over ln 2 (every other row and column is plenty).
  ratios_.clear();
  for (int row = rows / 2; row < rows; row += 2) {
    const float *residual = floor_residual_rows_.ptr<float>(row);
    for (int column = 0; column < columns; column += 2) {
      if (std::isfinite(residual[column])) ratios_.push_back(residual[column]);
    }
  }
  const float median = median_of(ratios_);
  noise_scale_ =
      std::isfinite(median) ? std::max(kMinNoiseScale, median / std::numbers::ln2_v<float>) : kMinNoiseScale;
}

float FloorBoundaryFinder::window_cost(int inner_row, float outer_row, int column,
                                       const vision::EdgeSelectionConfig &window) const {
  float sum = 0.0f;
  const int rows = rows_, columns = inner_.rows;
  for (int dc = -window.half_window_columns; dc <= window.half_window_columns; ++dc) {
    const int col = (column + dc + columns) % columns;
    for (int dr = -window.half_window_rows; dr <= window.half_window_rows; ++dr) {
      const int row = std::clamp(inner_row + dr, 0, rows - 1);
      sum += std::abs(inner_px(row, col) - gain(row, outer_row + static_cast<float>(dr)) *
                                               outer_at(outer_row + static_cast<float>(dr), col));
    }
  }
  return sum;
}

float FloorBoundaryFinder::window_deviation(int inner_row, int column,
                                            const vision::EdgeSelectionConfig &window) const {
  const int rows = rows_, columns = inner_.rows;
  const auto pixel = [&](int dr, int dc) {
    return inner_px(std::clamp(inner_row + dr, 0, rows - 1), (column + dc + columns) % columns);
  };
  float sum = 0.0f, count = 0.0f;
  for (int dc = -window.half_window_columns; dc <= window.half_window_columns; ++dc) {
    for (int dr = -window.half_window_rows; dr <= window.half_window_rows; ++dr)
      sum += pixel(dr, dc), count += 1.0f;
  }
  const float mean = sum / count;
  float deviation = 0.0f;
  for (int dc = -window.half_window_columns; dc <= window.half_window_columns; ++dc) {
    for (int dr = -window.half_window_rows; dr <= window.half_window_rows; ++dr)
      deviation += std::abs(pixel(dr, dc) - mean);
  }
  return deviation;
}

float FloorBoundaryFinder::row_vote(float residual_against, float residual_for) const {
  const float difference = (residual_against - residual_for) / noise_scale_;
  const float vote =
      std::copysign(std::min(std::max(0.0f, std::abs(difference) - kDeadZone), kMaxRowVote), difference);
  // A row neither hypothesis explains (a dust speck, a highlight, a third surface in
  // between) is an outlier under both: it says nothing about which is right.
  return std::min(residual_against, residual_for) > kOutlierResidual * noise_scale_ ? 0.0f : vote;
}

OMNISLAM_WIDE_VECTORS FloorBoundaryFinder::Verdict FloorBoundaryFinder::floor_or_vertical(
    int column, float edge_row, float contact_row, double *rows_llr) const {
  // Wald's sequential test, rows outwards from the edge. Rows inside the edge's own blur,
  // in either lobe, measure the sub-pixel placement of a steep edge rather than the
  // hypotheses, and do not vote. (The walk is the front-end's hottest loop, some 60 rows a
  // call on a textured floor: the votes of a block of rows are computed together, branch
  // free so that the compiler vectorises them, and then summed in order until a decision;
  // a row that does not vote adds 0.)
  const int base = static_cast<int>(edge_row);
  if (rows_llr != nullptr) *rows_llr = 0.0;
  if (base + 1 >= rows_) return Verdict::kUndecided;  // no surface tabulated that far
  const float fraction = edge_row - static_cast<float>(base);
  const float *near_base = geometry_->vertical_outer_rows(base);
  const float *far_base = geometry_->vertical_outer_rows(base + 1);
  const float *floor_residual = floor_residual_.ptr<float>(column);
  const float *inner = inner_.ptr<float>(column);
  const float *outer = outer_.ptr<float>(column);
  constexpr int kBlock = 16;
  std::array<float, kBlock> votes{};
  double llr = 0.0;
  for (int top = base - kEdgeBlurRows; top >= 0; top -= kBlock) {
    const int first = std::max(0, top - kBlock + 1), count = top - first + 1;
    for (int i = 0; i < count; ++i) {
      const int row = first + i;
      const float vertical_row = near_base[row] + fraction * (far_base[row] - near_base[row]);
      const float floor_row_residual = floor_residual[row];
      // Bitwise on ints, not &&: no branch, so the block stays vectorised.
      const bool votes_here = (static_cast<int>(std::isfinite(floor_row_residual)) &
                               static_cast<int>(std::isfinite(vertical_row)) &
                               static_cast<int>(std::abs(vertical_row - contact_row) > kEdgeBlurRows)) != 0;
      // (Row 0 stands in for the surface's outer row where the row does not vote.)
      const float surface_row = votes_here ? vertical_row : 0.0f;
      const float vertical_residual =
          std::abs(inner[row] - gain(row, surface_row) * interpolate(outer, surface_row));
      // Laplace log-likelihood ratio of the row, less a dead zone: two residuals of independent
      // noise differ by up to about twice the scale, and what the model itself leaves (sub-pixel
      // base, interpolation, the gain estimate) is smaller still; neither must add up over a
      // long uniform wall as if it were evidence.
      const float vote = row_vote(vertical_residual, floor_row_residual);
      votes[static_cast<std::size_t>(i)] = votes_here ? vote : 0.0f;
    }
    for (int i = count - 1; i >= 0; --i) {
      llr += kRowCorrelation * votes[static_cast<std::size_t>(i)];
      if (llr >= decision_llr_) return Verdict::kFloor;
      if (llr <= -decision_llr_) return Verdict::kVertical;
    }
  }
  if (rows_llr != nullptr) *rows_llr = llr;
  return Verdict::kUndecided;
}

FloorBoundaryFinder::Twin FloorBoundaryFinder::nearest_twin(float outer_row, int sign) const {
  Twin twin;
  for (std::size_t k = 0; k < column_outer_.size(); ++k) {
    const float offset = std::abs(column_outer_[k].row_subpx - outer_row);
    if (outer_sign_[k] == sign && offset < twin.offset) twin = {&column_outer_[k], offset};
  }
  return twin;
}

float FloorBoundaryFinder::below_floor(int column, std::size_t index, float floor_row, double floor_height_m,
                                       const RowTriangulator &triangulator) const {
  if (!std::isfinite(floor_row)) return kNaN;
  // The outer edge of the same polarity nearest below the floor's row, more than a floor
  // contact's margin off it, and no lower than a floor one camera height down would put it:
  // a surface under the floor plane (under a camera 1.05 m up, at 1-3 m, a step 0.18 m down
  // lies ~1.2 px below the floor's row, a sunken area 0.55 m down ~3 px, a floor 1.05 m
  // down ~5 px; a deeper drop, a stairwell, shows its first steps within that).
  const vision::EdgePoint *twin = nullptr;
  float offset = floor_row - geometry_->lowest_outer_row_at(column_inner_[index].row_subpx);
  for (std::size_t k = 0; k < column_outer_.size(); ++k) {
    const float below = floor_row - column_outer_[k].row_subpx;
    if (outer_sign_[k] == inner_sign_[index] && below > static_cast<float>(config_.contact_margin_px) &&
        below <= offset) {
      twin = &column_outer_[k];
      offset = below;
    }
  }
  if (twin == nullptr) return kNaN;
  const auto point = triangulator.triangulate(column, column_inner_[index].row_subpx, twin->row_subpx);
  return point && point->height_m < floor_height_m ? static_cast<float>(point->range_m) : kNaN;
}

const vision::EdgePoint *FloorBoundaryFinder::floor_contact(std::size_t index) const {
  const Twin twin =
      nearest_twin(geometry_->floor_outer_row_at(column_inner_[index].row_subpx), inner_sign_[index]);
  return twin.offset <= static_cast<float>(config_.contact_margin_px) ? twin.edge : nullptr;
}

bool FloorBoundaryFinder::floor_seen_beyond(std::size_t index, float contact_row, double rows_llr) const {
  // Each edge beyond with an outer twin on the floor is a feature of the floor if the floor
  // goes on, or of the surface standing at this edge if it does not; its twin's offset from
  // where each puts it is Laplace with the frame's placement error (measure_twin_spread),
  // so its log-likelihood ratio is the difference of the two offsets over that spread (the
  // nearest twin of the edge's polarity to the surface's row; none within kTwinSearchRows
  // counts as that far). Independent of the rows' smoothed residuals, it adds to their sum.
  if (!(twin_spread_px_ > 0.0f)) return false;
  const float base_row = column_inner_[index].row_subpx;
  double llr = rows_llr;
  for (std::size_t next = index + 1; next < column_inner_.size(); ++next) {
    const vision::EdgePoint *contact = contacts_[next];
    if (contact == nullptr) continue;
    const vision::EdgePoint &edge = column_inner_[next];
    const float surface_row = geometry_->vertical_outer_row_subpx(edge.row_subpx, base_row);
    // Near the base the two surfaces meet and the base's own twin stands for both.
    if (!std::isfinite(surface_row) ||
        std::abs(surface_row - contact_row) <= static_cast<float>(kEdgeBlurRows))
      continue;
    const float floor_offset = std::abs(contact->row_subpx - geometry_->floor_outer_row_at(edge.row_subpx));
    const float surface_offset =
        std::min(nearest_twin(surface_row, inner_sign_[next]).offset, kTwinSearchRows);
    llr += (surface_offset - floor_offset) / twin_spread_px_;
    if (llr >= decision_llr_) return true;
  }
  return false;
}

bool FloorBoundaryFinder::vertical_beyond(int column, std::size_t index) const {
  for (std::size_t next = index + 1; next < column_inner_.size(); ++next) {
    if (contacts_[next] == nullptr) continue;
    if (floor_or_vertical(column, column_inner_[next].row_subpx, contacts_[next]->row_subpx) ==
        Verdict::kVertical)
      return true;
  }
  return false;
}

bool FloorBoundaryFinder::farther_base_explains_better(int column, float base_row, float base_contact_row,
                                                       float farther_row, float farther_contact_row) const {
  // Rows between the two edges: floor (the farther hypothesis) against the surface standing
  // at the nearer base; rows beyond the farther edge: a surface standing there against one
  // standing at the nearer base. Same votes and thresholds as floor_or_vertical().
  double llr = 0.0;
  for (int row = static_cast<int>(base_row) - kEdgeBlurRows; row >= 0; --row) {
    const float near_row = geometry_->vertical_outer_row_at(row, base_row);
    if (!std::isfinite(near_row) || std::abs(near_row - base_contact_row) <= kEdgeBlurRows) continue;
    const bool between = static_cast<float>(row) > farther_row - static_cast<float>(kEdgeBlurRows);
    if (!between && static_cast<float>(row) > farther_row - static_cast<float>(2 * kEdgeBlurRows)) continue;
    float far_residual = kNaN;
    if (between) {
      far_residual = floor_residual_.ptr<float>(column)[row];
    } else {
      const float far_row = geometry_->vertical_outer_row_at(row, farther_row);
      if (std::isfinite(far_row) && std::abs(far_row - farther_contact_row) > kEdgeBlurRows)
        far_residual = std::abs(inner_px(row, column) - gain(row, far_row) * outer_at(far_row, column));
    }
    if (!std::isfinite(far_residual)) continue;
    const float near_residual =
        std::abs(inner_px(row, column) - gain(row, near_row) * outer_at(near_row, column));
    llr += kRowCorrelation * row_vote(near_residual, far_residual);
    if (llr >= decision_llr_) return true;
    if (llr <= -decision_llr_) return false;
  }
  return false;
}

const vision::EdgePoint *FloorBoundaryFinder::elevated_match(
    const vision::EdgePoint &edge, int column, const vision::EdgeImage &inner_edges,
    const vision::EdgeImage &outer_edges, std::span<const vision::EdgePoint> outer_column,
    const DisparityLimits &limits, const vision::EdgeSelectionConfig &window, float standing_outer_row,
    float floor_seen_outer_row) const {
  const DisparityBand &band = limits.per_inner_row[static_cast<std::size_t>(edge.row)];
  const float floor_row = geometry_->floor_outer_row_at(edge.row_subpx);
  const float floor_disparity = floor_row - edge.row_subpx;
  const int sign = polarity(inner_edges, edge.row, column);
  const auto margin = static_cast<float>(config_.contact_margin_px);
  const vision::EdgePoint *match = nullptr;
  float best_cost = std::numeric_limits<float>::infinity(), second_cost = best_cost;
  for (const vision::EdgePoint &outer : outer_column) {
    const float disparity = outer.row_subpx - edge.row_subpx;
    if (!band.contains(static_cast<float>(outer.row - edge.row)) ||
        polarity(outer_edges, outer.row, column) != sign)
      continue;
    if (std::isfinite(floor_disparity) && !(disparity > floor_disparity + margin)) continue;
    if (!(outer.row_subpx < floor_seen_outer_row - static_cast<float>(kEdgeBlurRows))) continue;
    const float cost = window_cost(edge.row, outer.row_subpx, column, window);
    if (cost < best_cost) {
      second_cost = best_cost, best_cost = cost, match = &outer;
    } else {
      second_cost = std::min(second_cost, cost);
    }
  }
  // Decisively better than the floor's prediction and than any other candidate: a table
  // top's two edges (top and underside) or a textured floor offer several near-equal ones.
  const auto decisive = [this, best_cost](float other_cost) {
    return !std::isfinite(other_cost) ||
           kWindowCorrelation * (other_cost - best_cost) / noise_scale_ >= decision_llr_;
  };
  if (match == nullptr || !decisive(second_cost)) return nullptr;
  // ... and than a featureless patch of the window's mean brightness: a match must explain
  // the window's structure (a speck on one mirror lobe has no twin, and the nearest edge of
  // the same polarity fits it hardly better than nothing).
  if (!decisive(window_deviation(edge.row, column, window))) return nullptr;
  if (std::isfinite(floor_row) && !decisive(window_cost(edge.row, floor_row, column, window))) return nullptr;
  if (std::isfinite(standing_outer_row) &&
      !decisive(window_cost(edge.row, standing_outer_row, column, window)))
    return nullptr;
  return match;
}

void FloorBoundaryFinder::measure_twin_spread(const vision::EdgeImage &inner_edges,
                                              const vision::EdgeImage &outer_edges,
                                              const vision::ColumnEdges &inner_candidates,
                                              const vision::ColumnEdges &outer_candidates) {
  // Every inner edge's nearest outer edge of the same polarity to where the floor puts it:
  // on the floor (most edges near the robot are) the offset is the two edges' sub-pixel
  // placement error; a robust spread of it (1.4826 MAD) measures that error for this frame.
  ratios_.clear();
  for (int column = 0; column < inner_candidates.columns(); column += 2) {
    const auto outer_column = outer_candidates.column(column);
    for (const vision::EdgePoint &edge : inner_candidates.column(column)) {
      if (edge.row < rows_ / 2) continue;
      const float floor_row = geometry_->floor_outer_row_at(edge.row_subpx);
      if (!std::isfinite(floor_row)) continue;
      const int sign = polarity(inner_edges, edge.row, column);
      float nearest = std::numeric_limits<float>::infinity();
      for (const vision::EdgePoint &outer : outer_column) {
        const float offset = std::abs(outer.row_subpx - floor_row);
        if (offset < nearest && polarity(outer_edges, outer.row, column) == sign) nearest = offset;
      }
      if (nearest <= kTwinSearchRows) ratios_.push_back(nearest);
    }
  }
  // The offsets are Laplace-distributed (measured on the degraded office: 86% within 0.5 px,
  // 10% within 0.5-1 px, 2-3% beyond, as a Laplace of scale 0.25 px gives and a Gaussian
  // does not), like the photometric residuals: the scale is the median over ln 2.
  const float median = median_of(ratios_);
  twin_spread_px_ = std::isfinite(median) ? median / std::numbers::ln2_v<float> : 0.0f;
  // Offsets the spread explains at the decision's error rate (the Laplace log-likelihood
  // ratio |offset| / scale reaching Wald's bound) do not by themselves put an edge above the
  // floor.
  ambiguous_offset_px_ = twin_spread_px_ * static_cast<float>(decision_llr_);
}

float FloorBoundaryFinder::floor_seen_outer_row(float farthest_floor_row) const {
  const float row = geometry_->floor_outer_row_at(farthest_floor_row);
  return std::isfinite(row) ? row : std::numeric_limits<float>::infinity();
}

int FloorBoundaryFinder::keep_drops_along_rims(FloorReach &reach) {
  // A drop's rim runs on across the columns beside it at like ranges; a twin below the floor
  // by chance does not (kDropRimColumns).
  std::vector<float> &drop_m = reach.drop_m;
  const int columns = static_cast<int>(drop_m.size());
  const auto at = [&](int column) { return drop_m[static_cast<std::size_t>((column + columns) % columns)]; };
  const auto alike = [&](int column) {  // column's drop goes on from the one before it
    const float range_m = at(column), before_m = at(column - 1);
    return std::isfinite(range_m) && std::isfinite(before_m) && drops_alike(range_m, before_m);
  };
  int first = 0;  // a run's first column: wrapped runs are walked whole
  while (first < columns && alike(first)) ++first;
  if (first == columns) first = 0;
  int kept = 0;
  for (int offset = 0; offset < columns;) {
    const int start = first + offset;
    if (!std::isfinite(at(start))) {
      ++offset;
      continue;
    }
    int length = 1;
    while (length < columns && alike(start + length)) ++length;
    for (int k = 0; k < length; ++k) {
      const auto c = static_cast<std::size_t>((start + k) % columns);
      if (length >= kDropRimColumns) {
        ++kept;
        if (std::isfinite(reach.free_m[c])) reach.free_m[c] = std::min(reach.free_m[c], drop_floor_m_[c]);
      } else {
        drop_m[c] = kNaN;
        reach.lower_m[c] = kNaN;
      }
    }
    offset += length;
  }
  return kept;
}

void FloorBoundaryFinder::close_rim_gaps(FloorReach &reach) {
  // A rim is one edge in the world: where two kept runs at like ranges are a few columns
  // apart (no longer than a run must be), the columns between saw no edge of the lower floor
  // and the rim runs on there too. Their floor is claimed only as far as the runs' columns
  // saw it (beyond, unknown: no drop is marked where none was seen).
  const std::vector<float> &drop_m = reach.drop_m;
  const int columns = static_cast<int>(drop_m.size());
  std::vector<int> &kept_columns = rim_columns_;
  kept_columns.clear();
  for (int column = 0; column < columns; ++column)
    if (std::isfinite(drop_m[static_cast<std::size_t>(column)])) kept_columns.push_back(column);
  if (kept_columns.size() < 2) return;
  for (std::size_t i = 0; i < kept_columns.size(); ++i) {
    const int from = kept_columns[i];
    const int to = kept_columns[(i + 1) % kept_columns.size()];
    const int gap = (to - from - 1 + columns) % columns;
    if (gap < 1 || gap > kDropRimColumns) continue;
    const float from_m = drop_floor_m_[static_cast<std::size_t>(from)];
    const float to_m = drop_floor_m_[static_cast<std::size_t>(to)];
    const float from_drop_m = drop_m[static_cast<std::size_t>(from)];
    const float to_drop_m = drop_m[static_cast<std::size_t>(to)];
    if (!drops_alike(std::max(from_drop_m, to_drop_m), std::min(from_drop_m, to_drop_m))) continue;
    for (int k = 1; k <= gap; ++k) {
      const auto c = static_cast<std::size_t>((from + k) % columns);
      const float t = static_cast<float>(k) / static_cast<float>(gap + 1);
      // A kept drop's column always has its floor-before range (0 where none was seen).
      if (std::isfinite(reach.free_m[c]))
        reach.free_m[c] = std::min(reach.free_m[c], from_m + t * (to_m - from_m));
    }
  }
}

BoundaryStats FloorBoundaryFinder::find(const FloorGeometry &geometry, const cv::Mat &inner_texture,
                                        const cv::Mat &outer_texture, const vision::EdgeImage &inner_edges,
                                        const vision::EdgeImage &outer_edges,
                                        const vision::ColumnEdges &inner_candidates,
                                        const vision::ColumnEdges &outer_candidates,
                                        const DisparityLimits &limits, const RowTriangulator &triangulator,
                                        const vision::EdgeSelectionConfig &window,
                                        std::vector<BoundaryPoint> &points, FloorReach &reach) {
  geometry_ = &geometry;
  prepare(inner_texture, outer_texture);
  measure_twin_spread(inner_edges, outer_edges, inner_candidates, outer_candidates);
  BoundaryStats stats;
  stats.noise_scale = noise_scale_;
  stats.twin_spread_px = twin_spread_px_;
  const double floor_height_m = -geometry_->camera_height_m();
  points.clear();
  const auto columns = static_cast<std::size_t>(inner_candidates.columns());
  for (std::vector<float> *range_m : {&reach.free_m, &reach.drop_m, &reach.lower_m, &drop_floor_m_})
    range_m->assign(columns, kNaN);
  for (int column = 0; column < inner_candidates.columns(); ++column) {
    const auto outer_edges_here = outer_candidates.column(column);
    float free_end_m = kNaN;          // an edge off the floor that nothing explains
    float farthest_floor_row = kNaN;  // the farthest edge found to be floor texture
    float boundary_m = kNaN;
    bool floor_reaches_boundary = false;  // a floor contact: the floor was seen up to it
    float drop_m = kNaN;                  // a lower floor seen beyond: the floor ended before this
    float lower_m = kNaN;                 // where in plan that lower floor was seen
    float floor_before_drop_m = kNaN;     // how far the floor was seen before the drop
    const auto inner_edges_here = inner_candidates.column(column);
    // 1. Is there an outer edge of the same polarity where the floor puts each edge? (Asked
    //    once per edge: steps 4 and 5 ask it again of the edges above.)
    column_inner_ = inner_edges_here;
    column_outer_ = outer_edges_here;
    inner_sign_.clear();
    outer_sign_.clear();
    for (const vision::EdgePoint &edge : inner_edges_here)
      inner_sign_.push_back(polarity(inner_edges, edge.row, column));
    for (const vision::EdgePoint &edge : outer_edges_here)
      outer_sign_.push_back(polarity(outer_edges, edge.row, column));
    contacts_.clear();
    for (std::size_t index = 0; index < inner_edges_here.size(); ++index)
      contacts_.push_back(floor_contact(index));
    for (std::size_t index = 0; index < inner_edges_here.size(); ++index) {
      const vision::EdgePoint &edge = inner_edges_here[index];
      const float floor_row = geometry_->floor_outer_row_at(edge.row_subpx);
      const vision::EdgePoint *contact = contacts_[index];
      // 2. If not, the outer edge nearer than the floor that looks most alike; it explains
      //    the edge only when it fits decisively better than the floor's prediction and any
      //    other candidate (a floor edge whose outer twin the detector missed is not a table
      //    top).
      const vision::EdgePoint *match =
          contact == nullptr ? elevated_match(edge, column, inner_edges, outer_edges, outer_edges_here,
                                              limits, window, kNaN, floor_seen_outer_row(farthest_floor_row))
                             : nullptr;
      if (contact == nullptr && match == nullptr && !std::isfinite(floor_row)) {
        ++stats.unexplained;
        if (!std::isfinite(free_end_m))
          free_end_m = static_cast<float>(geometry_->floor_range_at(edge.row_subpx));
        continue;
      }
      //    Without a twin on the floor or above it, a twin below it: a lower floor seen past a
      //    step down, whose rim this column's ray crossed before reaching it, at the floor
      //    level's range. The floor ended nearer. (The search itself goes on as before: a
      //    drop bounds the free floor, it is not a scan point.)
      if (contact == nullptr && match == nullptr && !std::isfinite(drop_m)) {
        lower_m = below_floor(column, index, floor_row, floor_height_m, triangulator);
        if (std::isfinite(lower_m)) {
          drop_m = static_cast<float>(geometry_->floor_range_at(edge.row_subpx));
          floor_before_drop_m = std::isfinite(farthest_floor_row)
                                    ? static_cast<float>(geometry_->floor_range_at(farthest_floor_row))
                                    : 0.0f;
        }
      }
      //    A twin less than the frame's placement error above the floor's row does not put
      //    the edge above the floor by itself: the pixels beyond decide, as in step 3.
      if (match != nullptr && std::abs(match->row_subpx - floor_row) <= ambiguous_offset_px_ &&
          floor_or_vertical(column, edge.row_subpx, floor_row) == Verdict::kFloor) {
        ++stats.floor_texture;
        farthest_floor_row = edge.row_subpx;
        continue;
      }
      if (match != nullptr) {
        const auto stereo = triangulator.triangulate(column, edge.row_subpx, match->row_subpx,
                                                     rows_per_column(outer_edges, *match, column));
        if (!stereo) continue;
        ++stats.elevated;
        points.push_back({.column = column,
                          .inner_row = edge.row_subpx,
                          .outer_row = match->row_subpx,
                          .range_m = stereo->range_m,
                          .height_m = stereo->height_m,
                          .elevated = true,
                          .azimuth_shift_rad = stereo->azimuth_shift_rad});
        boundary_m = static_cast<float>(stereo->range_m);
        break;
      }
      // 3. On the floor: floor going on, or a vertical surface standing here?
      float outer_row = contact != nullptr ? contact->row_subpx : floor_row;
      double rows_llr = 0.0;
      const Verdict verdict = floor_or_vertical(column, edge.row_subpx, outer_row, &rows_llr);
      // An undecided edge (the rows beyond too uniform to tell) was floor texture when the
      // floor is seen beyond it: the twins of the edges on the floor farther out, with the
      // rows' evidence, decisively place them on the floor rather than on a surface standing
      // here; or a surface decisively stands on the floor farther out.
      const bool floor_reaches_farther =
          verdict == Verdict::kUndecided && contact != nullptr &&
          (floor_seen_beyond(index, outer_row, rows_llr) || vertical_beyond(column, index));
      if (verdict == Verdict::kFloor || floor_reaches_farther) {
        ++stats.floor_texture;
        farthest_floor_row = edge.row_subpx;
        continue;
      }
      if (contact == nullptr) {
        // Neither lobe pair places it: a boundary needs an outer twin on the floor (or a
        // match above it); without one the edge stays unexplained and the search goes on.
        ++stats.unexplained;
        if (!std::isfinite(free_end_m))
          free_end_m = static_cast<float>(geometry_->floor_range_at(edge.row_subpx));
        continue;
      }
      // 4. Floor texture just in front of a wall leaves the wall to explain the rows above
      //    it, and a surface standing at the texture's range explains them almost as well.
      //    Would the next edge on the floor, as the base, explain them better (floor up to
      //    it)? Then this edge was floor texture too.
      const vision::EdgePoint *base = &edge;
      for (std::size_t next = index + 1; next < inner_edges_here.size(); ++next) {
        const vision::EdgePoint &farther = inner_edges_here[next];
        if (base->row - farther.row < 2 * kEdgeBlurRows) continue;
        const vision::EdgePoint *farther_contact = contacts_[next];
        if (farther_contact == nullptr) break;
        if (!farther_base_explains_better(column, base->row_subpx, outer_row, farther.row_subpx,
                                          farther_contact->row_subpx))
          break;
        ++stats.floor_texture;
        farthest_floor_row = base->row_subpx;
        base = &farther;
        outer_row = farther_contact->row_subpx;
      }
      ++stats.floor_contacts;
      if (verdict == Verdict::kUndecided) ++stats.undecided;
      // Its range from the row where the contact crosses this column's ray.
      const float contact_row =
          vision::ray_subpixel_row(inner_texture, inner_edges, *base, column, config_.contact_ray_sigma_px);
      const auto range_m = static_cast<float>(geometry_->floor_range_at(contact_row));
      BoundaryPoint point{column, contact_row, outer_row, range_m, floor_height_m, config_.floor_plane_range};
      if (!config_.floor_plane_range) {
        const auto stereo = triangulator.triangulate(column, base->row_subpx, outer_row);
        if (!stereo) continue;
        point.range_m = stereo->range_m;
        point.height_m = stereo->height_m;
        point.azimuth_shift_rad = stereo->azimuth_shift_rad;
      }
      // 5. A table top is nearer in plan than the floor seen under it, yet higher in the
      //    image: an edge above the floor boundary that matches decisively above the floor
      //    and lies nearer takes its place.
      for (std::size_t above = index + 1; above < inner_edges_here.size(); ++above) {
        const vision::EdgePoint &high = inner_edges_here[above];
        if (contacts_[above] != nullptr) continue;
        // Decisively better, too, than the surface standing at the boundary: an edge on
        // that wall (a picture, a door frame) whose outer twin was missed is not a table.
        const vision::EdgePoint *high_match =
            elevated_match(high, column, inner_edges, outer_edges, outer_edges_here, limits, window,
                           geometry_->vertical_outer_row_at(high.row, base->row_subpx), outer_row);
        if (high_match == nullptr) continue;
        const auto stereo = triangulator.triangulate(column, high.row_subpx, high_match->row_subpx,
                                                     rows_per_column(outer_edges, *high_match, column));
        if (stereo && stereo->range_m < point.range_m) {
          ++stats.elevated;
          point = {.column = column,
                   .inner_row = high.row_subpx,
                   .outer_row = high_match->row_subpx,
                   .range_m = stereo->range_m,
                   .height_m = stereo->height_m,
                   .elevated = true,
                   .azimuth_shift_rad = stereo->azimuth_shift_rad};
        }
      }
      points.push_back(point);
      boundary_m = static_cast<float>(point.range_m);
      floor_reaches_boundary = true;
      break;
    }
    // Free floor as far as it was seen: up to a floor contact (the floor reaches it), else up
    // to the first edge nothing explains or the farthest floor texture. An edge matched above
    // the floor before any contact (step 2) says nothing of the floor in front of it: under a
    // table the floor's texture shows it, but the face of a box, a sofa or a low platform
    // hides it (with its base in the blind zone or its front edge without contrast, the edge
    // matched is its back edge), so the floor is free only as far as it was seen, short of it.
    float &free_m = reach.free_m[static_cast<std::size_t>(column)];
    if (floor_reaches_boundary) {
      free_m = std::isfinite(free_end_m) ? std::min(free_end_m, boundary_m) : boundary_m;
    } else {
      free_m = std::isfinite(free_end_m) ? free_end_m
               : std::isfinite(farthest_floor_row)
                   ? static_cast<float>(geometry_->floor_range_at(farthest_floor_row))
                   : kNaN;
      if (std::isfinite(boundary_m) && std::isfinite(free_m)) free_m = std::min(free_m, boundary_m);
    }
    // A drop before any boundary, whose lower floor lies in front of it too (a lower floor
    // seen beyond the wall the column ends at is a twin below a floor edge by chance: the
    // wall's base whose own twin was missed).
    if (std::isfinite(drop_m) && !(boundary_m <= drop_m) && !(boundary_m < lower_m)) {
      reach.drop_m[static_cast<std::size_t>(column)] = drop_m;
      reach.lower_m[static_cast<std::size_t>(column)] = lower_m;
      drop_floor_m_[static_cast<std::size_t>(column)] = floor_before_drop_m;
    }
  }
  stats.drops = keep_drops_along_rims(reach);
  close_rim_gaps(reach);
  return stats;
}

}  // namespace omnislam::stereo
