#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/stereo/column_matching.hpp"
#include "omnislam/stereo/disparity_limits.hpp"
#include "omnislam/stereo/floor_boundary.hpp"
#include "omnislam/stereo/floor_geometry.hpp"
#include "omnislam/stereo/local_scan.hpp"
#include "omnislam/stereo/row_triangulator.hpp"
#include "omnislam/stereo/stereo_config.hpp"
#include "omnislam/vision/edge_detector.hpp"
#include "omnislam/vision/edge_selection.hpp"
#include "omnislam/vision/image_noise.hpp"
#include "omnislam/vision/panorama_unwarper.hpp"

/// @file
/// One omnidirectional image -> local scan (thesis sec. 3, steps 1-7).

namespace omnislam::stereo {

/// Working images and candidates of one lobe, reused from frame to frame.
struct LobeWork {
  cv::Mat panorama;  ///< CV_8UC1 rows_per_lobe x columns
  cv::Mat texture;   ///< CV_32FC1 in [0, 1] (Blackman-smoothed when configured)
  vision::EdgeImage edges;
  vision::ColumnEdges candidates;
  vision::SelectionStats selection;
  double image_noise_dn = 0.0;  ///< the frame's sensor noise (vision/image_noise.hpp)
};

/// Holds everything computed once per camera (remap tables, disparity bands, row
/// elevations, Blackman kernel) and the per-frame buffers. Not thread-safe: one instance
/// per thread. The stage methods are public so a profiler can time them; reconstruct()
/// runs them in order.
class ScanReconstructor {
 public:
  explicit ScanReconstructor(const ScanConfig &config = {});

  /// The whole reconstruction of one 8-bit grey image of the configured size. A wrong
  /// image gives status kBadImage and no points (no exception).
  [[nodiscard]] LocalScan reconstruct(const cv::Mat &image);
  /// The same, reusing `scan`'s storage.
  void reconstruct(const cv::Mat &image, LocalScan &scan);

  /// Stages, in order. Each reads what the previous one left in the working state.
  [[nodiscard]] bool accepts(const cv::Mat &image) const;
  void unwarp(const cv::Mat &image);  ///< step 1, both lobes, and the frame's noise
  void detect_edges();                ///< step 2, both lobes
  void select_edges();                ///< steps 3-4, both lobes
  void match();                       ///< step 5, every column pair (or the floor-boundary search)
  void triangulate(LocalScan &scan);  ///< steps 6-7, with the stats of all steps

  /// Exchanges the per-frame state of both lobes (what select_edges() leaves for match())
  /// with `inner` and `outer`, so that two instances with the same configuration can run
  /// the stages up to select_edges() and from match() on, e.g. in two threads.
  void swap_lobes(LobeWork &inner, LobeWork &outer) noexcept;

  [[nodiscard]] const ScanConfig &config() const { return config_; }
  [[nodiscard]] const mirror::MirrorModel &model() const { return model_; }
  [[nodiscard]] const DisparityLimits &disparity_limits() const { return limits_; }
  [[nodiscard]] const RowTriangulator &triangulator() const { return triangulator_; }
  [[nodiscard]] const LobeWork &inner() const { return inner_; }
  [[nodiscard]] const LobeWork &outer() const { return outer_; }
  [[nodiscard]] const std::vector<RowMatch> &matches() const { return matches_; }
  [[nodiscard]] const FloorGeometry &floor_geometry() const { return floor_geometry_; }

  /// Turns matched rows into scan points with the configured cut-offs and filter; shared
  /// with other matchers (e.g. a benchmark's StereoSGBM) so they are judged alike.
  void build_scan(const std::vector<RowMatch> &matches, LocalScan &scan);

 private:
  [[nodiscard]] bool floor_boundary() const {
    return config_.stereo.boundary == BoundaryMethod::kFloorBoundary;
  }
  void build_boundary_scan(LocalScan &scan);
  /// The noise floor's gain: a frame of pure noise through each lobe's panorama maps and its
  /// detector's smoothing and gradient gives, row by row, the Rayleigh scale of the gradient
  /// per grey level of pixel noise; times sqrt(2 ln(N / n)), the magnitude that noise exceeds
  /// at n (noise_edges_per_panorama) of the panorama's N pixels.
  void measure_noise_gain();
  /// Adds the point unless outside the cut-offs, with its range per pixel (of the floor
  /// plane's range when `floor_ranged`, else of the stereo range), at the column's azimuth
  /// moved by `azimuth_shift_rad` (RowTriangulator's ColumnPoint).
  void add_point(int column, double range_m, double height_m, double azimuth_shift_rad, float inner_row,
                 float outer_row, bool floor_ranged, bool elevated, LocalScan &scan);
  /// ScanPoint::range_per_px_m of a stereo point: the range's central difference over one
  /// pixel of each row (one-sided where the other side loses the intersection), combined
  /// as independent errors; infinite when neither side of a row intersects.
  [[nodiscard]] double stereo_range_per_px(int column, float inner_row, float outer_row,
                                           double range_m) const;
  /// The same for a floor contact ranged from the inner row and the floor plane.
  [[nodiscard]] double floor_range_per_px(float inner_row) const;

  ScanConfig config_;
  mirror::MirrorModel model_;
  vision::PanoramaUnwarper unwarper_;
  DisparityLimits limits_;
  RowTriangulator triangulator_;
  FloorGeometry floor_geometry_;
  vision::EdgeSelectionConfig selection_;  ///< the vision config's, with the method's edge count
  cv::Mat blackman_;
  std::vector<double> column_cos_;
  std::vector<double> column_sin_;
  std::vector<double> column_azimuth_rad_;
  vision::EdgeDetector inner_detector_;
  vision::EdgeDetector outer_detector_;
  /// Per lobe and panorama row, the least high threshold per grey level of the frame's noise
  /// (empty: no noise floor). See measure_noise_gain().
  std::vector<float> inner_noise_gain_;
  std::vector<float> outer_noise_gain_;
  std::vector<float> noise_floor_;
  vision::ImageNoiseMeter noise_meter_;
  LobeWork inner_;
  LobeWork outer_;
  std::vector<RowMatch> matches_;
  MatchStats match_stats_;
  FloorBoundaryFinder boundary_finder_;
  std::vector<BoundaryPoint> boundary_points_;
  FloorReach reach_;
  BoundaryStats boundary_stats_;
  std::vector<ScanPoint> filtered_;
};

}  // namespace omnislam::stereo
