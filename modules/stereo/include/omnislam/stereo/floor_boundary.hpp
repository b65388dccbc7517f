#pragma once

#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "omnislam/stereo/disparity_limits.hpp"
#include "omnislam/stereo/floor_geometry.hpp"
#include "omnislam/stereo/row_triangulator.hpp"
#include "omnislam/stereo/stereo_config.hpp"
#include "omnislam/vision/edge_detector.hpp"
#include "omnislam/vision/edge_selection.hpp"

/// @file
/// Where free floor ends, whatever the floor looks like. Replaces "the nearest horizontal
/// edge of each column" (thesis sec. 3 step 3), which on a textured floor is a tile joint
/// or a shadow edge, by a test of what the two lobes see beyond each edge.
///
/// Per column, the horizontal edges of the inner panorama are visited from the robot
/// outwards:
///  1. Is the edge on the floor? A floor point seen at inner row e is seen by the outer
///     lobe at the row the mirror model predicts from the camera height alone; an edge on
///     the floor has an outer edge of the same polarity there (within contact_margin_px).
///  2. If it is not, the edge may be above the floor (a table top, a shelf): the outer edge
///     nearer than the floor that explains its window decisively better than the floor's
///     prediction and than every other candidate is triangulated and ends the search. With
///     no such match the edge is unexplained (the free range stops there). A match whose
///     outer row lies within the frame's own placement error of the floor's row (the
///     spread of floor edges' twins about it, measured per frame on the rows nearest the
///     robot) does not by itself put the edge above the floor: if the pixels beyond are
///     decisively floor (step 3's test), the edge is floor texture.
///  3. If it is, which hypothesis explains the pixels beyond it in both lobes: the floor
///     going on, or a vertical surface standing at the edge's range? Each row above the
///     edge compares the photometric residual of the two hypotheses (inner pixel against
///     the outer pixel each predicts, after a radial gain model between the lobes), and a
///     sequential probability ratio test (Wald) accumulates them until one hypothesis wins
///     at the configured error rate. Floor wins: the edge is floor texture, and evidence of
///     free floor; the search goes on. The vertical surface wins, or the column ends
///     undecided (a uniform wall explains both equally): the edge is where the floor ends,
///     unless (undecided) the floor is seen beyond it: the edges farther out whose outer
///     twins sit on the floor place them there decisively rather than on a surface standing
///     at the edge (each twin's offset from either row, over the frame's placement error, adds
///     to the rows' evidence; at 3-5 m, where few rows lie between floor texture and a wall,
///     the twins tell what the smoothed rows cannot), or an edge farther out stands on the
///     floor and is decisively a vertical surface: the floor reaches it. A row neither
///     hypothesis explains (a dust speck, a highlight, a third surface in between) does not
///     vote. Its range is the floor range of the edge row (the floor plane is far more
///     precise than the stereo disparity: ~16 mm per row at 1-2 m against ~130 mm per pixel
///     of disparity, mirror.md sec. 9).
///  4. Unless the next edge on the floor, as the base, explains the rows beyond better
///     (floor texture just in front of a wall).
///  5. And unless an edge higher up matches decisively above the floor and lies nearer in
///     plan (a table top is nearer than the floor seen under it, yet higher in the image).
/// The residual noise scale is measured per frame (median floor residual of the rows
/// nearest the robot), so no threshold is in intensity units.

namespace omnislam::stereo {

/// A point where free floor ends in one column.
struct BoundaryPoint {
  int column = 0;
  float inner_row = 0.0f;
  float outer_row = 0.0f;
  double range_m = 0.0;
  double height_m = 0.0;           ///< relative to the pinhole (the floor is -camera_height_m for a contact)
  bool floor_ranged = false;       ///< ranged from the floor plane (inner row only), not by stereo
  bool elevated = false;           ///< an edge above the floor (step 2 or 5), not a floor contact
  double azimuth_shift_rad = 0.0;  ///< off the column's azimuth (a misaligned rig's stereo point)
};

struct BoundaryStats {
  int floor_texture = 0;        ///< edges the floor hypothesis explained
  int floor_contacts = 0;       ///< boundaries on the floor (vertical surface or undecided)
  int undecided = 0;            ///< of which the test ran out of rows
  int elevated = 0;             ///< boundaries above the floor (triangulated)
  int unexplained = 0;          ///< edges off the floor without an outer match
  int drops = 0;                ///< of which below the floor: a lower floor past a step down
  float noise_scale = 0.0f;     ///< residual scale used by the test (intensity in [0, 1])
  float twin_spread_px = 0.0f;  ///< the lobes' sub-pixel placement error (Laplace scale, rows)
};

/// What each panorama column showed of the floor (NaN where nothing).
struct FloorReach {
  /// How far the floor was seen to be free.
  std::vector<float> free_m;
  /// Where a lower floor seen beyond showed the floor ending before any boundary (a step
  /// down): the floor level's range of the ray that reached it (the rim is nearer).
  std::vector<float> drop_m;
  /// The range in plan of the lower floor's point that ray reached: from drop_m to here the
  /// ray ran below the floor's level, over the lower floor.
  std::vector<float> lower_m;
};

/// Scratch images between frames; not thread-safe (one per thread).
class FloorBoundaryFinder {
 public:
  explicit FloorBoundaryFinder(const FloorBoundaryConfig &config = {});

  /// Finds the boundary of every column. `inner`/`outer` textures are CV_32FC1 in [0, 1];
  /// the candidates are every horizontal edge of each column, nearest first; `reach` gets what
  /// each column showed of the floor (FloorReach).
  BoundaryStats find(const FloorGeometry &geometry, const cv::Mat &inner_texture,
                     const cv::Mat &outer_texture, const vision::EdgeImage &inner_edges,
                     const vision::EdgeImage &outer_edges, const vision::ColumnEdges &inner_candidates,
                     const vision::ColumnEdges &outer_candidates, const DisparityLimits &limits,
                     const RowTriangulator &triangulator, const vision::EdgeSelectionConfig &window,
                     std::vector<BoundaryPoint> &points, FloorReach &reach);

 private:
  /// Smoothed column-major textures, the lobes' gain, the floor residuals, the noise scale.
  void prepare(const cv::Mat &inner_texture, const cv::Mat &outer_texture);
  void fit_lobe_gain();
  void measure_noise_scale();
  /// Wald's test over the rows above `edge_row`: floor going on, a vertical surface standing
  /// at the edge's floor range, or neither decisively (the column ran out of rows; then
  /// `rows_llr`, if given, gets the log-likelihood ratio the rows reached, positive for floor).
  enum class Verdict { kFloor, kVertical, kUndecided };
  [[nodiscard]] Verdict floor_or_vertical(int column, float edge_row, float contact_row,
                                          double *rows_llr = nullptr) const;
  /// Whether the floor is decisively seen beyond the current column's edge `index`: the rows'
  /// log-likelihood ratio `rows_llr` plus that of each farther edge with an outer twin on the
  /// floor (the twin's offset from a surface standing at the edge against its offset from
  /// the floor, in units of the frame's placement error).
  [[nodiscard]] bool floor_seen_beyond(std::size_t index, float contact_row, double rows_llr) const;
  /// Whether edge `index` of the current column is a surface below the floor: its nearest
  /// same-polarity outer edge below the floor's row, beyond the contact margin and no lower
  /// than a floor one camera height down would put it, triangulates under the floor plane.
  /// Returns that point's range in plan, NaN when it is not.
  [[nodiscard]] float below_floor(int column, std::size_t index, float floor_row, double floor_height_m,
                                  const RowTriangulator &triangulator) const;
  /// Keeps the drops along a rim (a run of at least kDropRimColumns columns with like ranges;
  /// NaN for the others) and stops their columns' free floor where it was seen before the
  /// drop; returns how many were kept.
  int keep_drops_along_rims(FloorReach &reach);
  /// Between two kept runs at like ranges at most kDropRimColumns apart, the columns that saw
  /// no drop are free only as far as the runs' columns saw the floor before their drops
  /// (interpolated between the runs' ends). After keep_drops_along_rims.
  void close_rim_gaps(FloorReach &reach);
  std::vector<int> rim_columns_;     ///< close_rim_gaps' scratch: the columns with a kept drop
  std::vector<float> drop_floor_m_;  ///< per column, how far the floor was seen before its drop
  struct Twin {
    const vision::EdgePoint *edge = nullptr;
    float offset = std::numeric_limits<float>::infinity();
  };
  /// The current column's outer edge of polarity `sign` nearest `outer_row` and its offset
  /// from it (nullptr and infinity when the column has none).
  [[nodiscard]] Twin nearest_twin(float outer_row, int sign) const;
  [[nodiscard]] float outer_at(float row, int column) const;
  /// One column-major line (a column of a lobe) at a fractional row, clamped to the lobe.
  [[nodiscard]] float interpolate(const float *line, float row) const;
  /// Vote of one row for the hypothesis with `residual_for` (positive) over the other,
  /// in residual scales, less the dead zone, capped.
  [[nodiscard]] float row_vote(float residual_against, float residual_for) const;
  /// The outer edge of the same polarity where the floor puts the current column's edge
  /// `index`, or nullptr.
  [[nodiscard]] const vision::EdgePoint *floor_contact(std::size_t index) const;
  /// The outer edge nearer than the floor that explains `edge`'s window decisively better
  /// than the floor's prediction (an edge above the floor), or nullptr. If
  /// `standing_outer_row` is finite (the row a surface standing at the boundary puts the
  /// edge at), decisively better than that too. Only outer edges above
  /// `floor_seen_outer_row` are candidates: below it the outer lobe shows floor the column
  /// has already verified, and one pixel does not show two things.
  [[nodiscard]] const vision::EdgePoint *elevated_match(
      const vision::EdgePoint &edge, int column, const vision::EdgeImage &inner_edges,
      const vision::EdgeImage &outer_edges, std::span<const vision::EdgePoint> outer_column,
      const DisparityLimits &limits, const vision::EdgeSelectionConfig &window, float standing_outer_row,
      float floor_seen_outer_row) const;
  /// The outer row from which on (downwards) the outer lobe shows floor already verified in
  /// this column: the floor row of the farthest floor-texture edge (+inf when there is none).
  [[nodiscard]] float floor_seen_outer_row(float farthest_floor_row) const;
  /// The spread of the offset between floor edges' outer twins and the floor's row, and the
  /// offset below which a twin does not decisively put an edge above the floor.
  void measure_twin_spread(const vision::EdgeImage &inner_edges, const vision::EdgeImage &outer_edges,
                           const vision::ColumnEdges &inner_candidates,
                           const vision::ColumnEdges &outer_candidates);
  /// Whether an edge of the current column beyond `index` stands on the floor (it has an
  /// outer twin there) and is decisively a vertical surface.
  [[nodiscard]] bool vertical_beyond(int column, std::size_t index) const;
  /// Whether floor up to the farther edge and a surface standing there explain the rows
  /// beyond the nearer base better than a surface standing at the nearer base.
  [[nodiscard]] bool farther_base_explains_better(int column, float base_row, float base_contact_row,
                                                  float farther_row, float farther_contact_row) const;
  [[nodiscard]] float inner_px(int row, int column) const { return inner_.ptr<float>(column)[row]; }
  /// r_o^2 - r_i^2, radii in units of 512 px: the regressor of the lobes' gain.
  [[nodiscard]] float radius_term(int inner_row, float outer_row) const;
  /// Gain-compensated SAD of the inner window at `inner_row` and the outer one at
  /// `outer_row` (fractional), on the smoothed textures.
  [[nodiscard]] float window_cost(int inner_row, float outer_row, int column,
                                  const vision::EdgeSelectionConfig &window) const;
  /// SAD of the inner window against its own mean: the cost of explaining it by nothing.
  [[nodiscard]] float window_deviation(int inner_row, int column,
                                       const vision::EdgeSelectionConfig &window) const;

  const FloorGeometry *geometry_ = nullptr;  ///< of the current find() call
  FloorBoundaryConfig config_;
  double decision_llr_ = 0.0;
  int rows_ = 0;
  cv::Mat smoothed_inner_, smoothed_outer_, floor_residual_rows_;  ///< row-major scratch
  cv::Mat inner_;           ///< smoothed inner texture, transposed: one matrix row per column
  cv::Mat outer_;           ///< smoothed outer texture, transposed
  cv::Mat floor_residual_;  ///< |inner - gain * outer at the floor row|, transposed like them
  std::vector<float> inner_radius_squared_;
  std::vector<float> floor_gain_;  ///< gain() of each inner row and its floor outer row
  /// Brightness of the inner lobe over the outer lobe for the same scene point, seen at
  /// image radii r_i and r_o: reflectance ratio times radial falloff to first order,
  /// gain_at_centre_ + gain_slope_ * (r_o^2 - r_i^2) (radii in units of 512 px).
  [[nodiscard]] float gain(int inner_row, float outer_row) const;
  float gain_at_centre_ = 1.0f;
  float gain_slope_ = 0.0f;
  std::vector<float> ratios_;
  std::vector<const vision::EdgePoint *> contacts_;  ///< per edge of the current column
  std::span<const vision::EdgePoint> column_inner_;  ///< the current column's edges, nearest first
  std::span<const vision::EdgePoint> column_outer_;
  std::vector<int> inner_sign_, outer_sign_;  ///< their polarities (+1: brighter upwards)
  float noise_scale_ = 0.0f;
  float twin_spread_px_ = 0.0f;
  float ambiguous_offset_px_ = 0.0f;
};

}  // namespace omnislam::stereo
