#include "omnislam/io/dataset.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera_fields.hpp"
#include "yaml_fields.hpp"

namespace omnislam::io {
namespace {

// The images pattern goes to snprintf with one int: allow exactly one %d with optional
// zero flag and width, and %% escapes, nothing else (no %s, %n, ...).
bool is_frame_pattern(const std::string &pattern) {
  int fields = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (++i < pattern.size() && pattern[i] == '%') continue;
    if (i < pattern.size() && pattern[i] == '0') ++i;
    std::size_t digits = 0;
    while (i < pattern.size() && pattern[i] >= '0' && pattern[i] <= '9' && digits < 2) ++i, ++digits;
    if (i >= pattern.size() || pattern[i] != 'd') return false;
    ++fields;
  }
  return fields == 1;
}

}  // namespace

std::filesystem::path DatasetInfo::image(int frame) const {
  std::vector<char> name(images.size() + 32);
  std::snprintf(name.data(), name.size(), images.c_str(), frame);
  return dir / name.data();
}

DatasetInfo read_dataset_info(const std::filesystem::path &dir) {
  const std::string file = (dir / "dataset.yaml").string();
  const YAML::Node root = detail::load_yaml(file);
  detail::YamlSection top(root, "", file);
  DatasetInfo info;
  info.dir = dir;
  top.read("name", info.name);
  // The camera line `omnislam calibrate target` writes carries the camera height the floor
  // boards measured (consistent with the rig it fitted); the top-level key is the
  // dataset's own. Both may be given only if they agree.
  double calibrated_height_m = std::numeric_limits<double>::quiet_NaN();
  if (top.has("camera")) {
    detail::YamlSection camera(top.node("camera"), "camera", file);
    detail::read_camera_fields(camera, info.camera);
    camera.read("camera_height_m", calibrated_height_m);
    if (camera.has("camera_height_m") && !(calibrated_height_m > 0.0))
      camera.fail("camera_height_m", "must be positive");
    camera.finish();
  }
  if (top.has("mirror")) {
    std::string mirror;
    top.read("mirror", mirror);
    if (mirror != "thesis-2008") top.fail("mirror", "must be thesis-2008 (the only mirror supported)");
  }
  const bool height_given = top.has("camera_height_m");
  top.read("camera_height_m", info.camera_height_m);
  if (height_given && !(info.camera_height_m > 0.0)) top.fail("camera_height_m", "must be positive");
  if (!std::isnan(calibrated_height_m)) {
    if (height_given && calibrated_height_m != info.camera_height_m) {
      top.fail("camera_height_m", "disagrees with camera.camera_height_m (" +
                                      std::to_string(calibrated_height_m) +
                                      "): keep one (a calibration's is what its floor boards measured)");
    }
    info.camera_height_m = calibrated_height_m;
  }
  top.read("frames", info.frames);
  top.read("rate_hz", info.rate_hz);
  top.read("images", info.images);
  const auto path_of = [&](const char *key, std::filesystem::path &path) {
    std::string relative;
    top.read(key, relative);
    if (!relative.empty()) path = dir / relative;
  };
  path_of("groundtruth", info.groundtruth);
  path_of("odometry", info.odometry);
  path_of("odometry_exact", info.odometry_exact);
  path_of("floorplan", info.floorplan);
  if (info.frames < 0) top.fail("frames", "must be >= 0");
  if (!is_frame_pattern(info.images)) {
    top.fail("images", "must be a path with one frame-number field like %06d (and %% for a literal %)");
  }
  return info;
}

}  // namespace omnislam::io
