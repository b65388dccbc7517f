#include "calibrate_command.hpp"

#include "calibrate_level.hpp"
#include "calibrate_target.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "omnislam/calib/rim.hpp"
#include "omnislam/calib/sensitivity.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/image_file.hpp"

namespace omnislam::app {
namespace {

struct RimOptions {
  std::vector<std::string> images;
  std::string config;
  std::string out;
};

std::string circle_text(const std::optional<calib::CircleFit> &circle) {
  if (!circle) return "not found";
  char text[160];
  std::snprintf(text, sizeof text, "(%.3f, %.3f) r %.2f px, rms %.3f px, %d/%d rays", circle->centre_px.x(),
                circle->centre_px.y(), circle->radius_px, circle->rms_px, circle->inliers, circle->points);
  return text;
}

void run_rim(const RimOptions &options) {
  const auto start = std::chrono::steady_clock::now();
  const io::Config config = options.config.empty() ? io::Config{} : io::load_config(options.config);
  const mirror::MirrorConfig &camera = config.scan.camera;
  std::vector<calib::RimEstimate> estimates;
  int failed = 0;
  for (const std::string &file : options.images) {
    calib::RimEstimate estimate;
    try {
      estimate = calib::find_rim(io::read_camera_image(file, camera), camera);
    } catch (const std::runtime_error &error) {
      estimate.error = error.what();
    }
    if (!estimate.ok()) {
      std::fprintf(stderr, "omnislam calibrate rim: %s: %s\n", file.c_str(), estimate.error.c_str());
      ++failed;
      continue;
    }
    std::printf("%s: centre (%.3f, %.3f) +- (%.3f, %.3f) px; rim %s; central disc %s\n", file.c_str(),
                estimate.centre_px.x(), estimate.centre_px.y(), estimate.centre_sigma_px.x(),
                estimate.centre_sigma_px.y(), circle_text(estimate.rim).c_str(),
                circle_text(estimate.central).c_str());
    estimates.push_back(estimate);
  }
  if (failed > 0) {
    throw std::runtime_error(std::to_string(failed) + " of " + std::to_string(options.images.size()) +
                             " image(s) gave no centre; nothing written");
  }
  // The images' mean; its uncertainty is the larger of what the fits say and what the
  // images' spread says (a rig that moves between images shows in the spread).
  const auto n = static_cast<double>(estimates.size());
  Eigen::Vector2d mean = Eigen::Vector2d::Zero(), fit_variance = Eigen::Vector2d::Zero();
  for (const calib::RimEstimate &e : estimates) {
    mean += e.centre_px / n;
    fit_variance += e.centre_sigma_px.cwiseProduct(e.centre_sigma_px) / (n * n);
  }
  Eigen::Vector2d spread = Eigen::Vector2d::Zero();
  for (const calib::RimEstimate &e : estimates) spread += (e.centre_px - mean).cwiseAbs2();
  spread = n > 1.0 ? Eigen::Vector2d((spread / (n - 1.0)).cwiseSqrt()) : Eigen::Vector2d::Zero();
  const Eigen::Vector2d sigma = fit_variance.cwiseSqrt().cwiseMax(spread / std::sqrt(n));
  const Eigen::Vector2d configured(camera.center_u_px, camera.center_v_px);
  const double elapsed_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "centre over %zu image(s): (%.3f, %.3f) +- (%.3f, %.3f) px (images' spread %.3f, %.3f px); "
      "configured (%.3f, %.3f): %.3f px off; %.0f ms\n",
      estimates.size(), mean.x(), mean.y(), sigma.x(), sigma.y(), spread.x(), spread.y(), configured.x(),
      configured.y(), (mean - configured).norm(), elapsed_ms);
  std::ofstream out(options.out);
  out << "# omnislam calibrate rim over " << estimates.size() << " image(s): centre 1-sigma u " << sigma.x()
      << " v " << sigma.y() << " px\n";
  char line[128];
  std::snprintf(line, sizeof line, "camera: {center_px: [%.4f, %.4f]}\n", mean.x(), mean.y());
  out << line;
  if (!out) throw std::runtime_error(options.out + ": cannot write");
  std::printf("wrote %s\n", options.out.c_str());
}

void run_sensitivity(const std::string &config_file) {
  const io::Config config = config_file.empty() ? io::Config{} : io::load_config(config_file);
  std::printf(
      "Range error of a wall's base on the floor per parameter error (camera %.2f m above the floor):\n\n",
      config.scan.camera_height_m);
  std::printf("| parameter | error | floor plane, 1 / 2 / 4 m | stereo, 1 / 2 / 4 m |\n|---|---|---|---|\n");
  const auto millimetres = [](const std::array<double, 3> &errors) {
    char text[64];
    std::snprintf(text, sizeof text, "%.1f / %.1f / %.1f mm", errors[0] * 1000.0, errors[1] * 1000.0,
                  errors[2] * 1000.0);
    return std::string(text);
  };
  for (const calib::RangeSensitivity &row :
       calib::range_sensitivity(config.scan.camera, config.scan.camera_height_m)) {
    std::printf("| %s | %s | %s | %s |\n", row.parameter.c_str(), row.step.c_str(),
                millimetres(row.floor_plane_m).c_str(), millimetres(row.stereo_m).c_str());
  }
}

}  // namespace

void add_calibrate_command(CLI::App &app) {
  auto *calibrate = app.add_subcommand("calibrate", "calibrate the rig (camera and mirror) from images");
  calibrate->require_subcommand(1);
  auto *rim = calibrate->add_subcommand(
      "rim", "image centre from the mirror's rim and central disc in the rig's own images (no target)");
  auto options = std::make_shared<RimOptions>();
  rim->add_option("IMAGE", options->images, "8-bit images of the rig (any scene)")->required();
  rim->add_option("--config", options->config, "YAML configuration (camera: where the search starts)");
  rim->add_option("--out", options->out, "YAML file to write (camera: {center_px: [u, v]})")->required();
  rim->callback([options] { run_rim(*options); });
  add_calibrate_target(*calibrate);
  add_calibrate_level(*calibrate);
  auto *sensitivity = calibrate->add_subcommand(
      "sensitivity", "range error at 1, 2 and 4 m per unit error of each rig parameter (Markdown table)");
  auto config_file = std::make_shared<std::string>();
  sensitivity->add_option("--config", *config_file, "YAML configuration (camera, camera_height_m)");
  sensitivity->callback([config_file] { run_sensitivity(*config_file); });
}

}  // namespace omnislam::app
