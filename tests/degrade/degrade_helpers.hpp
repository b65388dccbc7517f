#pragma once

#include <catch2/catch.hpp>
#include <cmath>
#include <opencv2/core.hpp>
#include <string_view>

#include "omnislam/degrade/degradation.hpp"

// Shared by the degrade tests: configs with one factor, images, comparisons.
namespace omnislam::degrade::test {

/// The default config with only the factors of `list` enabled.
inline DegradationConfig only(std::string_view list) {
  DegradationConfig config;
  REQUIRE(apply_factor_list(list, config).empty());
  return config;
}

inline cv::Mat flat(int level, int size = 1024) { return cv::Mat(size, size, CV_8UC1, cv::Scalar(level)); }

inline bool identical(const cv::Mat &a, const cv::Mat &b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

/// Radius of pixel (u, v) about the default centre (511.5, 511.5).
inline double radius_px(int u, int v) { return std::hypot(u - 511.5, v - 511.5); }

}  // namespace omnislam::degrade::test
