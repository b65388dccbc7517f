#include <catch2/catch.hpp>
#include <vector>

#include "omnislam/stereo/column_matching.hpp"

using namespace omnislam::stereo;
using omnislam::vision::EdgePoint;

namespace {

// Textures with the same intensity profile along every column, shifted by `shift` rows
// in the outer one: an edge at inner row r is at outer row r + shift.
struct Pair {
  cv::Mat inner = cv::Mat(225, 360, CV_32FC1, cv::Scalar(0.3f));
  cv::Mat outer = cv::Mat(225, 360, CV_32FC1, cv::Scalar(0.3f));
  void band(int inner_top, int height, float value, int shift) {
    inner.rowRange(inner_top, inner_top + height).setTo(value);
    outer.rowRange(inner_top + shift, inner_top + shift + height).setTo(value);
  }
};

DisparityLimits uniform_band(float min_px, float max_px) {
  DisparityLimits limits;
  limits.per_inner_row.assign(225, DisparityBand{min_px, max_px});
  limits.min_px = min_px;
  limits.max_px = max_px;
  return limits;
}

EdgePoint at(int row) { return {row, static_cast<float>(row), 100.0f}; }

}  // namespace

TEST_CASE("DP matches corresponding edges in order and leaves the unmatched occluded", "[stereo][dp]") {
  Pair pair;
  pair.band(100, 20, 0.9f, 12);  // edges at inner 100 and 120 -> outer 112 and 132
  pair.band(150, 10, 0.6f, 12);  // edges at 150 and 160 -> 162 and 172
  const std::vector<EdgePoint> inner{at(160), at(150), at(120), at(100)};  // bottom-up
  // The outer list lacks the edge of inner 150 and has a spurious one at 140.
  const std::vector<EdgePoint> outer{at(172), at(140), at(132), at(112)};
  StereoConfig config;
  config.subpixel = SubpixelMethod::kNone;
  std::vector<RowMatch> matches;
  MatchStats stats;
  match_column(inner, outer, 7, pair.inner, pair.outer, uniform_band(8, 16), {}, config, matches, stats);
  REQUIRE(matches.size() == 3);
  CHECK(matches[0].inner_row == 160.0f);
  CHECK(matches[0].outer_row == 172.0f);
  CHECK(matches[1].inner_row == 120.0f);
  CHECK(matches[1].outer_row == 132.0f);
  CHECK(matches[2].inner_row == 100.0f);
  CHECK(matches[2].outer_row == 112.0f);
  CHECK(matches[0].column == 7);
  CHECK(matches[0].cost == Approx(0.0f).margin(1e-5));
  CHECK(stats.matched == 3);
  CHECK(stats.occluded_inner == 1);
  CHECK(stats.occluded_outer == 1);
}

TEST_CASE("DP respects the disparity band and the occlusion cost", "[stereo][dp]") {
  Pair pair;
  pair.band(100, 30, 0.9f, 12);
  const std::vector<EdgePoint> inner{at(130), at(100)};
  const std::vector<EdgePoint> outer{at(142), at(112)};
  std::vector<RowMatch> matches;
  MatchStats stats;
  StereoConfig config;
  config.subpixel = SubpixelMethod::kNone;
  // A band that excludes d = 12 forbids both true matches; none is made.
  match_column(inner, outer, 0, pair.inner, pair.outer, uniform_band(20, 40), {}, config, matches, stats);
  CHECK(matches.empty());
  CHECK(stats.admissible_pairs == 0);
  // With occlusion free, leaving everything unmatched is as cheap as matching: no match
  // is worth a non-negative cost.
  pair.inner.setTo(0.3f);
  pair.outer.setTo(0.35f);  // every match now costs 21 * 0.05 = 1.05
  config.occlusion_cost = 0.5;
  match_column(inner, outer, 0, pair.inner, pair.outer, uniform_band(8, 16), {}, config, matches, stats);
  CHECK(matches.empty());
  config.occlusion_cost = 2.5;  // two occlusions (5.0) cost more than a poor match
  match_column(inner, outer, 0, pair.inner, pair.outer, uniform_band(8, 16), {}, config, matches, stats);
  CHECK(matches.size() == 2);
}

TEST_CASE("sub-pixel refinement: edge peaks and the SAD cost curve", "[stereo][dp]") {
  // The outer edge sits between rows: a half-intensity row blends the two sides.
  cv::Mat inner(225, 360, CV_32FC1, cv::Scalar(0.2f)), outer(225, 360, CV_32FC1, cv::Scalar(0.2f));
  inner.rowRange(0, 100).setTo(0.8f);
  outer.rowRange(0, 112).setTo(0.8f);
  outer.row(112).setTo(0.5f);  // the step is at 112.5 in the outer, 100 in the inner
  const std::vector<EdgePoint> inner_points{{100, 99.7f, 50.0f}};
  const std::vector<EdgePoint> outer_points{{112, 112.2f, 50.0f}};
  StereoConfig config;
  std::vector<RowMatch> matches;
  MatchStats stats;
  config.subpixel = SubpixelMethod::kEdgePeak;
  match_column(inner_points, outer_points, 0, inner, outer, uniform_band(8, 16), {}, config, matches, stats);
  REQUIRE(matches.size() == 1);
  CHECK(matches[0].inner_row == 99.7f);
  CHECK(matches[0].outer_row == 112.2f);
  matches.clear();
  config.subpixel = SubpixelMethod::kCostCurve;
  match_column(inner_points, outer_points, 0, inner, outer, uniform_band(8, 16), {}, config, matches, stats);
  REQUIRE(matches.size() == 1);
  // SAD places the outer edge 12.5 rows below the integer inner row; that disparity is
  // applied at the refined inner row.
  CHECK(matches[0].inner_row == 99.7f);
  CHECK(matches[0].outer_row == Approx(99.7f + 12.5f).margin(0.01));
}
