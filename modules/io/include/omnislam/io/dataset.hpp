#pragma once

#include <filesystem>
#include <string>

#include "omnislam/mirror/mirror_config.hpp"

/// @file
/// A rendered dataset directory as architecture.md "Dataset format" describes it
/// (dataset.yaml, images/, groundtruth.tum, odometry*.tum, floorplan.csv).

namespace omnislam::io {

struct DatasetInfo {
  std::filesystem::path dir;
  std::string name;
  mirror::MirrorConfig camera;   ///< the thesis mirror with the dataset's camera keys
  double camera_height_m = 1.0;  ///< pinhole above the floor
  int frames = 0;
  double rate_hz = 10.0;
  std::string images = "images/%06d.png";  ///< printf pattern of the frame number (1-based)
  std::filesystem::path groundtruth;       ///< absolute paths; empty when not given
  std::filesystem::path odometry;
  std::filesystem::path odometry_exact;
  std::filesystem::path floorplan;

  /// The image file of frame `frame` (1-based).
  [[nodiscard]] std::filesystem::path image(int frame) const;
};

/// Reads DIR/dataset.yaml. Keys outside the contract are ignored (the format may grow);
/// a contract key of the wrong type, a missing file, or a mirror other than
/// "thesis-2008" throws std::runtime_error naming the file and line.
[[nodiscard]] DatasetInfo read_dataset_info(const std::filesystem::path &dir);

}  // namespace omnislam::io
