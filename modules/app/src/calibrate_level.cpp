#include "calibrate_level.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "omnislam/calib/level_fit.hpp"
#include "omnislam/calib/sensitivity.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/stereo/floor_twins.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

namespace omnislam::app {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
// Passes stop once the correction is within its own 1-sigma (the contacts found move a
// little with the tilt, so later passes scatter by about that), or after kMaxPasses.
constexpr double kSettledSigmas = 1.0;
constexpr int kMaxPasses = 6;

struct LevelOptions {
  std::vector<std::string> images;
  std::string config;
  double max_tilt_deg = 1.0;
  bool with_height = false;
  std::string out;
};

// The floor contacts of every image with an unambiguous outer twin, ranged by stereo, in the
// level frame of `scan_config`.
std::vector<calib::FloorContact> floor_contacts(const stereo::ScanConfig &scan_config,
                                                const std::vector<cv::Mat> &images, double max_tilt_rad,
                                                std::vector<int> &per_image) {
  stereo::ScanReconstructor reconstructor(scan_config);
  std::vector<calib::FloorContact> contacts;
  per_image.assign(images.size(), 0);
  stereo::LocalScan scan;
  for (std::size_t frame = 0; frame < images.size(); ++frame) {
    reconstructor.reconstruct(images[frame], scan);
    for (const Eigen::Vector3d &point :
         stereo::unambiguous_floor_contacts(reconstructor, scan, max_tilt_rad)) {
      contacts.push_back({point, static_cast<int>(frame)});
      ++per_image[frame];
    }
  }
  return contacts;
}

// 1-sigma of the tilt (x, y) in rad.
Eigen::Vector2d tilt_sigma(const calib::LevelFitResult &fit) {
  return {std::sqrt(fit.covariance(1, 1)), std::sqrt(fit.covariance(2, 2))};
}

void report(const calib::LevelFitResult &fit, const Eigen::Vector2d &tilt, const Eigen::Vector2d &configured,
            const stereo::ScanConfig &scan_config) {
  const Eigen::Vector2d sigma = tilt_sigma(fit);
  std::printf(
      "\nlevel tilt: x %.4f deg, y %.4f deg, 1 sigma %.4f / %.4f deg (over %d image(s), %d of %d floor "
      "contacts fit the plane, their heights' robust scale %.1f mm); configured %.4f / %.4f deg\n",
      tilt.x() * kDeg, tilt.y() * kDeg, sigma.x() * kDeg, sigma.y() * kDeg, fit.frames, fit.inliers,
      fit.contacts, fit.residual_scale_m * 1e3, configured.x() * kDeg, configured.y() * kDeg);
  std::printf("floor by stereo: %.4f +- %.4f m below the pinhole (camera_height_m configured %.4f m)\n",
              -fit.floor_z_m, std::sqrt(fit.covariance(0, 0)), scan_config.camera_height_m);
  // What the tilt's uncertainty costs the floor-plane ranges (calibrate sensitivity's model).
  Eigen::Matrix<double, calib::kTargetParameters, calib::kTargetParameters> covariance =
      Eigen::Matrix<double, calib::kTargetParameters, calib::kTargetParameters>::Zero();
  covariance.bottomRightCorner<2, 2>() = fit.covariance.bottomRightCorner<2, 2>();
  mirror::MirrorConfig camera = scan_config.camera;
  camera.rig.level_tilt_x_rad = tilt.x();
  camera.rig.level_tilt_y_rad = tilt.y();
  const calib::RangeUncertainty range =
      calib::range_uncertainty(camera, covariance, scan_config.camera_height_m);
  std::printf(
      "range error this uncertainty implies, wall base on the floor at 1 / 2 / 4 m (1 sigma):\n"
      "  floor plane %.1f / %.1f / %.1f mm, stereo %.1f / %.1f / %.1f mm\n",
      range.floor_plane_m[0] * 1e3, range.floor_plane_m[1] * 1e3, range.floor_plane_m[2] * 1e3,
      range.stereo_m[0] * 1e3, range.stereo_m[1] * 1e3, range.stereo_m[2] * 1e3);
}

void run_level(const LevelOptions &options) {
  const auto start = std::chrono::steady_clock::now();
  const io::Config config = options.config.empty() ? io::Config{} : io::load_config(options.config);
  stereo::ScanConfig scan_config = config.scan;
  // The floor-boundary search finds the contacts; stereo ranges them (floor_twins.hpp).
  scan_config.stereo.boundary = stereo::BoundaryMethod::kFloorBoundary;
  if (!(options.max_tilt_deg > 0.0 && options.max_tilt_deg <= 5.0))
    throw std::runtime_error("--max-tilt-deg must be in (0, 5]");
  std::vector<cv::Mat> images;
  for (const std::string &file : options.images)
    images.push_back(io::read_camera_image(file, scan_config.camera));

  const Eigen::Vector2d configured(scan_config.camera.rig.level_tilt_x_rad,
                                   scan_config.camera.rig.level_tilt_y_rad);
  Eigen::Vector2d tilt = configured;
  calib::LevelFitResult fit;
  std::vector<int> per_image;
  // The contacts found move a little with the tilt they are found with, so the estimate
  // still moves from pass to pass: the last pass's correction is added to the uncertainty.
  Eigen::Vector2d last_correction = Eigen::Vector2d::Zero();
  for (int pass = 1; pass <= kMaxPasses; ++pass) {
    scan_config.camera.rig.level_tilt_x_rad = tilt.x();
    scan_config.camera.rig.level_tilt_y_rad = tilt.y();
    const std::vector<calib::FloorContact> contacts =
        floor_contacts(scan_config, images, options.max_tilt_deg / kDeg, per_image);
    if (pass == 1) {
      for (std::size_t i = 0; i < images.size(); ++i) {
        if (per_image[i] == 0)
          std::fprintf(stderr, "omnislam calibrate level: %s: skipped: no floor contact found\n",
                       options.images[i].c_str());
        else
          std::printf("%s: %d floor contacts\n", options.images[i].c_str(), per_image[i]);
      }
    }
    fit = calib::fit_level(contacts);
    if (!fit.ok) throw std::runtime_error("the fit failed: " + fit.message + "; nothing written");
    const Eigen::Vector2d correction(fit.tilt_x_rad, fit.tilt_y_rad);
    tilt = calib::compose_level_tilt(tilt, correction);
    last_correction = correction;
    const Eigen::Vector2d sigma = tilt_sigma(fit);
    std::printf("pass %d: tilt corrected by %.4f / %.4f deg (1 sigma %.4f / %.4f) to %.4f / %.4f deg\n", pass,
                correction.x() * kDeg, correction.y() * kDeg, sigma.x() * kDeg, sigma.y() * kDeg,
                tilt.x() * kDeg, tilt.y() * kDeg);
    if ((correction.array().abs() <= kSettledSigmas * sigma.array()).all()) break;
  }
  fit.covariance(1, 1) += last_correction.x() * last_correction.x();
  fit.covariance(2, 2) += last_correction.y() * last_correction.y();
  report(fit, tilt, configured, scan_config);

  std::ofstream out(options.out);
  const Eigen::Vector2d sigma = tilt_sigma(fit);
  char text[256];
  std::snprintf(
      text, sizeof text,
      "# omnislam calibrate level over %d image(s), %d floor contacts: 1 sigma %.4f / %.4f deg; the floor by "
      "stereo %.4f m below the pinhole\n",
      fit.frames, fit.inliers, sigma.x() * kDeg, sigma.y() * kDeg, -fit.floor_z_m);
  out << text;
  std::snprintf(text, sizeof text, "camera: {level_tilt_deg: [%.4f, %.4f]", tilt.x() * kDeg, tilt.y() * kDeg);
  out << text;
  if (options.with_height) {
    std::snprintf(text, sizeof text, ", camera_height_m: %.4f", -fit.floor_z_m);
    out << text;
  }
  out << "}\n";
  if (!out) throw std::runtime_error(options.out + ": cannot write");
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s (%.1f s)\n", options.out.c_str(), elapsed_s);
}

}  // namespace

void add_calibrate_level(CLI::App &calibrate) {
  auto *command = calibrate.add_subcommand(
      "level", "the rig's tilt off level from the floor its images show, ranged by stereo (no target)");
  auto options = std::make_shared<LevelOptions>();
  command
      ->add_option("IMAGE", options->images, "8-bit images of the rig on the floor it drives on (any room)")
      ->required();
  command->add_option("--config", options->config,
                      "YAML configuration (camera: the rig, its level_tilt_deg the start; camera_height_m)");
  command->add_option("--max-tilt-deg", options->max_tilt_deg,
                      "how far off the configured tilt the floor is looked for (default 1): a contact counts "
                      "when one outer edge alone lies where the floor could put it within this tilt");
  command->add_flag("--with-height", options->with_height,
                    "also write camera_height_m: the floor's depth below the pinhole by stereo with this rig "
                    "(consistent with its mirror and focal length; a taped height is not)");
  command->add_option("--out", options->out, "YAML file to write (camera: {level_tilt_deg: [x, y]})")
      ->required();
  command->callback([options] { run_level(*options); });
}

}  // namespace omnislam::app
