#include "omnislam/calib/target_detect.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "corner_refine.hpp"

namespace omnislam::calib {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// A lobe unrolled: panorama (x, y) <-> image radius and azimuth about the configured centre.
struct Unrolled {
  double centre_u = 0.0, centre_v = 0.0;
  double outer_radius_px = 0.0;  // at row 0
  double px_per_row = 1.0;       // image radius per panorama row
  double rad_per_column = 0.0;
  cv::Mat panorama;

  [[nodiscard]] cv::Point2d raw(const cv::Point2f &p) const {
    const double radius = outer_radius_px - p.y * px_per_row;
    const double phi = p.x * rad_per_column;
    return {centre_u + radius * std::cos(phi), centre_v + radius * std::sin(phi)};
  }
};

Unrolled unroll(const cv::Mat &image, const mirror::MirrorConfig &camera, double inner_radius_px,
                double outer_radius_px, const TargetDetectConfig &config, double azimuth_scale) {
  Unrolled lobe;
  lobe.centre_u = camera.center_u_px;
  lobe.centre_v = camera.center_v_px;
  lobe.outer_radius_px = outer_radius_px + config.margin_px;
  lobe.px_per_row = 1.0 / config.radial_scale;
  // Columns `azimuth_scale` panorama pixels apart per image pixel at the annulus's middle.
  const double middle_px = 0.5 * (inner_radius_px + outer_radius_px);
  lobe.rad_per_column = 1.0 / (middle_px * azimuth_scale);
  const int rows =
      static_cast<int>((outer_radius_px - inner_radius_px + 2.0 * config.margin_px) * config.radial_scale);
  const int columns = static_cast<int>((360.0 + config.wrap_deg) * kDegToRad / lobe.rad_per_column);
  cv::Mat map_x(rows, columns, CV_32F), map_y(rows, columns, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < columns; ++x) {
      const cv::Point2d at = lobe.raw(cv::Point2f(static_cast<float>(x), static_cast<float>(y)));
      map_x.at<float>(y, x) = static_cast<float>(at.x);
      map_y.at<float>(y, x) = static_cast<float>(at.y);
    }
  }
  cv::remap(image, lobe.panorama, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return lobe;
}

using Grid = std::vector<cv::Point2f>;  // row-major, corners_x per row

// The grid renumbered as one of its four symmetries that keep its shape: 0 as it is, 1
// reversed along x, 2 along y, 3 both (a half turn).
Grid renumbered(const Grid &grid, int nx, int ny, int symmetry) {
  Grid out(grid.size());
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      const int sx = (symmetry & 1) ? nx - 1 - x : x;
      const int sy = (symmetry & 2) ? ny - 1 - y : y;
      out[static_cast<std::size_t>(y * nx + x)] = grid[static_cast<std::size_t>(sy * nx + sx)];
    }
  }
  return out;
}

// The inner lobe's numbering: x along increasing azimuth (panorama columns), y downwards
// where it can, so the numbering does not depend on where the detector started.
Grid canonical(const Grid &grid, int nx, int ny) {
  for (int symmetry = 0; symmetry < 4; ++symmetry) {
    const Grid g = renumbered(grid, nx, ny, symmetry);
    const cv::Point2f along_x = g[static_cast<std::size_t>(nx - 1)] - g[0];
    const cv::Point2f along_y = g[static_cast<std::size_t>((ny - 1) * nx)] - g[0];
    const bool x_right = std::abs(along_x.x) >= std::abs(along_x.y) ? along_x.x > 0.0f : along_x.y > 0.0f;
    const bool y_down = std::abs(along_y.y) >= std::abs(along_y.x) ? along_y.y > 0.0f : along_y.x < 0.0f;
    if (x_right && y_down) return g;
  }
  return grid;
}

// The outer lobe's grid numbered like the inner one's: the symmetry whose corners, about
// their mean, lie nearest the inner corners about theirs (same azimuths, same vertical order).
Grid matched(const Grid &outer, const Grid &inner, int nx, int ny) {
  const auto centred = [](const Grid &g) {
    cv::Point2f mean(0.0f, 0.0f);
    for (const cv::Point2f &p : g) mean += p / static_cast<float>(g.size());
    Grid out;
    for (const cv::Point2f &p : g) out.push_back(p - mean);
    return out;
  };
  const Grid reference = centred(inner);
  Grid best = outer;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int symmetry = 0; symmetry < 4; ++symmetry) {
    const Grid g = renumbered(outer, nx, ny, symmetry);
    const Grid c = centred(g);
    double cost = 0.0;
    for (std::size_t i = 0; i < c.size(); ++i) cost += cv::norm(c[i] - reference[i]);
    if (cost < best_cost) best_cost = cost, best = g;
  }
  return best;
}

std::optional<Grid> find_grid(const cv::Mat &panorama, const cv::Size &pattern, int flags) {
  Grid corners;
  if (!cv::findChessboardCornersSB(panorama, pattern, corners, flags)) return std::nullopt;
  return corners;
}

// The board in a lobe's panorama: found first at half resolution (a quarter of the work),
// then at full resolution in a window round it; where the coarse search fails (small
// squares), over the whole panorama.
std::optional<Grid> find_grid(const Unrolled &lobe, const TargetGeometry &target) {
  const cv::Size pattern(target.corners_x(), target.corners_y());
  const int fine = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY;
  cv::Mat half;
  cv::resize(lobe.panorama, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  if (const std::optional<Grid> coarse = find_grid(half, pattern, cv::CALIB_CB_NORMALIZE_IMAGE)) {
    const cv::Rect box = cv::boundingRect(*coarse);
    // Two squares' margin round the corners' box (the board's outer squares and border).
    const int margin = 2 * 2 * std::max(box.width / pattern.width, box.height / pattern.height) + 8;
    const cv::Rect window = cv::Rect(2 * box.x - margin, 2 * box.y - margin, 2 * box.width + 2 * margin,
                                     2 * box.height + 2 * margin) &
                            cv::Rect(0, 0, lobe.panorama.cols, lobe.panorama.rows);
    if (std::optional<Grid> grid = find_grid(lobe.panorama(window), pattern, fine)) {
      for (cv::Point2f &p : *grid)
        p += cv::Point2f(static_cast<float>(window.x), static_cast<float>(window.y));
      return grid;
    }
  }
  return find_grid(lobe.panorama, pattern, fine);
}

// The panorama's corners in the raw image.
std::vector<cv::Point2f> raw_corners(const Unrolled &lobe, const Grid &grid) {
  std::vector<cv::Point2f> raw;
  for (const cv::Point2f &p : grid) raw.emplace_back(lobe.raw(p));
  return raw;
}

// One square's step along the board's x and y at corner (x, y) of a row-major grid in the
// image: the central difference of its neighbours, one-sided at the board's edge.
Eigen::Matrix2d square_axes(const std::vector<cv::Point2f> &raw, int nx, int ny, int x, int y) {
  const auto at = [&](int cx, int cy) {
    const cv::Point2f &p = raw[static_cast<std::size_t>(cy * nx + cx)];
    return Eigen::Vector2d(p.x, p.y);
  };
  const auto step = [&](int dx, int dy) -> Eigen::Vector2d {
    const int x0 = std::max(x - dx, 0), x1 = std::min(x + dx, nx - 1);
    const int y0 = std::max(y - dy, 0), y1 = std::min(y + dy, ny - 1);
    return (at(x1, y1) - at(x0, y0)) / static_cast<double>(std::max(x1 - x0, y1 - y0));
  };
  Eigen::Matrix2d axes;
  axes.col(0) = step(1, 0);
  axes.col(1) = step(0, 1);
  return axes;
}

// Each corner fitted in the raw image (corner_refine.hpp); where the fit fails the
// detector's corner stays.
std::vector<cv::Point2f> refined(const cv::Mat &image, std::vector<cv::Point2f> raw, int nx, int ny,
                                 const TargetDetectConfig &config) {
  detail::CornerRefineConfig refine;
  refine.window = config.refine_window_squares;
  const std::vector<cv::Point2f> detected = raw;
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      cv::Point2f &p = raw[static_cast<std::size_t>(y * nx + x)];
      const std::optional<Eigen::Vector2d> corner = detail::refine_corner(
          image, Eigen::Vector2d(p.x, p.y), square_axes(detected, nx, ny, x, y), refine);
      if (corner) p = cv::Point2f(static_cast<float>(corner->x()), static_cast<float>(corner->y()));
    }
  }
  return raw;
}

void add_corners(TargetView &view, mirror::Lobe lobe, const std::vector<cv::Point2f> &raw) {
  for (std::size_t i = 0; i < raw.size(); ++i)
    view.corners.push_back({static_cast<int>(i), lobe, {raw[i].x, raw[i].y}});
}

}  // namespace

TargetDetection detect_target(const cv::Mat &image, const mirror::MirrorConfig &camera,
                              const TargetGeometry &target, const TargetDetectConfig &config) {
  TargetDetection detection;
  if (image.empty() || image.type() != CV_8UC1) {
    detection.error = "not an 8-bit grey image";
    return detection;
  }
  const double split_px = camera.discard_px + camera.rows_per_lobe;
  const double rim_px = split_px + camera.rows_per_lobe;
  const Unrolled inner =
      unroll(image, camera, camera.discard_px, split_px, config, config.inner_azimuth_scale);
  const Unrolled outer = unroll(image, camera, split_px, rim_px, config, config.outer_azimuth_scale);
  const int nx = target.corners_x(), ny = target.corners_y();
  std::optional<Grid> inner_grid = find_grid(inner, target);
  std::optional<Grid> outer_grid = find_grid(outer, target);
  if (inner_grid) inner_grid = canonical(*inner_grid, nx, ny);
  if (outer_grid)
    outer_grid = inner_grid ? matched(*outer_grid, *inner_grid, nx, ny) : canonical(*outer_grid, nx, ny);
  const auto corners_of = [&](const Unrolled &lobe, const Grid &grid) {
    const std::vector<cv::Point2f> raw = raw_corners(lobe, grid);
    return config.refine_window_squares > 0.0 ? refined(image, raw, nx, ny, config) : raw;
  };
  if (inner_grid) {
    add_corners(detection.view, mirror::Lobe::kInner, corners_of(inner, *inner_grid));
    detection.inner_corners = nx * ny;
  }
  if (outer_grid) {
    add_corners(detection.view, mirror::Lobe::kOuter, corners_of(outer, *outer_grid));
    detection.outer_corners = nx * ny;
  }
  if (!inner_grid && !outer_grid) {
    detection.error = "no " + std::to_string(target.squares_x) + " x " + std::to_string(target.squares_y) +
                      " chessboard found in either lobe";
  }
  return detection;
}

}  // namespace omnislam::calib
