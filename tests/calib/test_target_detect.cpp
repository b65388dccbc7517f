#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "omnislam/calib/target_detect.hpp"
#include "omnislam/calib/target_fit.hpp"

using omnislam::calib::TargetGeometry;
using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorConfig;

namespace {

// datasets/calib-target-rig: scripts/render-target's images of an 8 x 6 board of 45 mm squares
// through a misaligned rig, with the truth (see its README).
const std::string kData = std::string(OMNISLAM_DEFAULT_DATASETS) + "/calib-target-rig";

struct Truth {
  MirrorConfig camera;
  std::vector<Eigen::Isometry3d> T_camera_board;
  std::vector<bool> on_floor;
};

Truth read_truth(const std::string &directory) {
  const YAML::Node root = YAML::LoadFile(directory + "/truth.yaml");
  Truth truth;
  const YAML::Node camera = root["camera"];
  truth.camera.center_u_px = camera["center_px"][0].as<double>();
  truth.camera.center_v_px = camera["center_px"][1].as<double>();
  truth.camera.rig.focal_scale = camera["focal_scale"].as<double>();
  truth.camera.rig.mirror_dz_mm = camera["mirror_dz_mm"].as<double>();
  truth.camera.rig.mirror_tilt_x_rad = camera["mirror_tilt_deg"][0].as<double>() * std::numbers::pi / 180.0;
  truth.camera.rig.mirror_tilt_y_rad = camera["mirror_tilt_deg"][1].as<double>() * std::numbers::pi / 180.0;
  truth.camera.rig.mirror_offset_x_mm = camera["mirror_offset_mm"][0].as<double>();
  truth.camera.rig.mirror_offset_y_mm = camera["mirror_offset_mm"][1].as<double>();
  for (const YAML::Node &view : root["views"]) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = view["T_camera_board"][r][c].as<double>();
    truth.T_camera_board.push_back(T);
    truth.on_floor.push_back(view["on_floor"].as<bool>());
  }
  return truth;
}

std::string image_path(const std::string &directory, std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "/%06zu.png", index + 1);
  return directory + name;
}

}  // namespace

TEST_CASE("target detection: corners of rendered boards in both lobes, sub-pixel",
          "[calib][target][detect]") {
  const Truth truth = read_truth(kData);
  const TargetGeometry target;
  const omnislam::mirror::RigModel rig(truth.camera);
  double sum = 0.0;
  int corners = 0, both = 0;
  // Two boards held, two on the floor (each image takes ~3 s: the whole set is the CLI's test).
  for (const std::size_t i : {0u, 4u, 12u, 19u}) {
    REQUIRE(i < truth.T_camera_board.size());
    const cv::Mat image = cv::imread(image_path(kData, i), cv::IMREAD_GRAYSCALE);
    REQUIRE(!image.empty());
    // Detected with the designed rig: the search does not need the truth.
    const auto detection = omnislam::calib::detect_target(image, MirrorConfig{}, target);
    CAPTURE(i, detection.error);
    CHECK(detection.ok());
    both += detection.inner_corners > 0 && detection.outer_corners > 0 ? 1 : 0;
    // Each corner where the true rig images it, up to the board's numbering symmetry.
    double best = std::numeric_limits<double>::infinity();
    const int nx = target.corners_x(), ny = target.corners_y();
    for (int symmetry = 0; symmetry < 4; ++symmetry) {
      double view_sum = 0.0;
      for (const auto &corner : detection.view.corners) {
        const int x = corner.index % nx, y = corner.index / nx;
        const int index = ((symmetry & 2) ? ny - 1 - y : y) * nx + ((symmetry & 1) ? nx - 1 - x : x);
        const auto pixel = rig.project(corner.lobe, truth.T_camera_board[i] * target.corner_m(index));
        REQUIRE(pixel);
        view_sum +=
            std::pow(pixel->u_px - corner.pixel.u_px, 2) + std::pow(pixel->v_px - corner.pixel.v_px, 2);
      }
      best = std::min(best, view_sum);
    }
    sum += best;

    corners += static_cast<int>(detection.view.corners.size());
  }
  const double rms_px = std::sqrt(sum / std::max(corners, 1));
  CAPTURE(rms_px, corners, both);
  // Measured: 0.10 px over these four with each corner fitted in the raw image (0.12 px as
  // the detector put them); over all 24 images 0.085 px in the inner lobe and 0.12 in the
  // outer, whose squares on the floor are ~4 px tall and slanted (their corners' position
  // along the edges is poorly defined: random, 0.14 px rms, which the fit averages).
  CHECK(rms_px < 0.15);
  CHECK(both == 4);
}
