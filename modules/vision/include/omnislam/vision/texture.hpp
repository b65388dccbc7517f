#pragma once

#include <opencv2/core.hpp>

/// @file
/// The image the similarity cost reads (thesis sec. 3 step 4): the panorama as float
/// intensity in [0, 1], optionally smoothed by the normalised symmetric 7x7 Blackman FIR
/// filter of the thesis (UsaBlackman).

namespace omnislam::vision {

/// The 1-D Blackman window of `taps` samples, normalised to sum 1. Its outer product with
/// itself is the thesis's symmetric 2-D filter (separable, so it is applied as two passes).
/// The classic window is zero at both ends, so 7 taps have 5 non-zero weights.
[[nodiscard]] cv::Mat blackman_kernel(int taps = 7);

/// Converts an 8-bit panorama into `texture` (CV_32FC1, [0, 1]); with `kernel` non-empty
/// the result is smoothed (replicated rows, the azimuth seam is not wrapped).
void make_texture(const cv::Mat &panorama, const cv::Mat &kernel, cv::Mat &texture);

}  // namespace omnislam::vision
