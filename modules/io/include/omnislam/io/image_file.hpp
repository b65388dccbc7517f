#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "omnislam/mirror/mirror_config.hpp"

/// @file
/// Reading camera images (8-bit PNG/BMP/..., grey or colour) for the reconstruction, and
/// writing them as PNG.

namespace omnislam::io {

/// Reads `file` as an 8-bit grey image (colour is converted) and checks its size against
/// the camera. Throws std::runtime_error naming the file when it is missing, unreadable,
/// empty or of another size than camera.image_width_px x camera.image_height_px.
[[nodiscard]] cv::Mat read_camera_image(const std::filesystem::path &file,
                                        const mirror::MirrorConfig &camera);

/// Writes `image` (8-bit, grey or colour) to `file` as PNG, lossless; the parent directory
/// must exist. Throws std::runtime_error naming the file when it cannot be written.
void write_png_image(const std::filesystem::path &file, const cv::Mat &image);

}  // namespace omnislam::io
