#include "calibrate_target.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "omnislam/calib/rim.hpp"
#include "omnislam/calib/sensitivity.hpp"
#include "omnislam/calib/target_detect.hpp"
#include "omnislam/calib/target_fit.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/image_file.hpp"

namespace omnislam::app {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
constexpr int kMinViews = 4;

struct TargetOptions {
  std::vector<std::string> images;
  std::string config;
  std::string squares = "8x6";
  double square_mm = 45.0;
  bool hold_level = false;
  std::string out;
};

calib::TargetGeometry geometry_of(const TargetOptions &options) {
  calib::TargetGeometry target;
  char x = 0;
  if (std::sscanf(options.squares.c_str(), "%d%c%d", &target.squares_x, &x, &target.squares_y) != 3 ||
      (x != 'x' && x != 'X') || target.squares_x < 3 || target.squares_y < 3) {
    throw std::runtime_error("--squares " + options.squares + ": must be COLSxROWS squares, each at least 3");
  }
  if (!(options.square_mm > 0.0)) throw std::runtime_error("--square-mm must be positive");
  target.square_m = options.square_mm / 1000.0;
  return target;
}

// What the images gave: each image's corners (or why not) and the rim circles' mean.
struct Detected {
  std::vector<calib::TargetView> views;
  std::vector<std::string> files;  // per view
  calib::RimCircles rim;
  int skipped = 0;
};

// The mean of the circles found, its sigma the larger of the fits' and the images' spread.
std::optional<calib::CircleFit> mean_circle(const std::vector<calib::CircleFit> &circles) {
  if (circles.empty()) return std::nullopt;
  const auto n = static_cast<double>(circles.size());
  calib::CircleFit mean;
  Eigen::Vector2d fit_variance = Eigen::Vector2d::Zero();
  for (const calib::CircleFit &c : circles) {
    mean.centre_px += c.centre_px / n;
    mean.radius_px += c.radius_px / n;
    fit_variance += c.centre_sigma_px.cwiseAbs2() / n;
  }
  Eigen::Vector2d spread = Eigen::Vector2d::Zero();
  for (const calib::CircleFit &c : circles) spread += (c.centre_px - mean.centre_px).cwiseAbs2();
  spread = n > 1.0 ? Eigen::Vector2d((spread / (n - 1.0)).cwiseSqrt()) : Eigen::Vector2d::Zero();
  mean.centre_sigma_px = fit_variance.cwiseSqrt().cwiseMax(spread);
  return mean;
}

Detected detect(const TargetOptions &options, const mirror::MirrorConfig &camera,
                const calib::TargetGeometry &target) {
  Detected detected;
  std::vector<calib::CircleFit> rims, centrals;
  for (const std::string &file : options.images) {
    const cv::Mat image = io::read_camera_image(file, camera);  // unreadable, wrong size: fatal
    const calib::TargetDetection detection = calib::detect_target(image, camera, target);
    if (!detection.ok()) {
      std::fprintf(stderr, "omnislam calibrate target: %s: skipped: %s\n", file.c_str(),
                   detection.error.c_str());
      ++detected.skipped;
      continue;
    }
    std::printf("%s: %d corners in the inner lobe, %d in the outer\n", file.c_str(), detection.inner_corners,
                detection.outer_corners);
    detected.views.push_back(detection.view);
    detected.files.push_back(file);
    const calib::RimEstimate rim = calib::find_rim(image, camera);
    if (rim.rim) rims.push_back(*rim.rim);
    if (rim.central) centrals.push_back(*rim.central);
  }
  detected.rim = {mean_circle(rims), mean_circle(centrals)};
  return detected;
}

void print_report(const calib::TargetFitResult &fit, const Detected &detected, const io::Config &config) {
  const mirror::MirrorConfig &c = fit.camera;
  const auto &s = fit.sigma;
  std::printf("\nviews: %d used", fit.views_used);
  int floor = 0;
  for (const bool f : fit.on_floor) floor += f ? 1 : 0;
  std::printf(" (%d on the floor, %d held), %d image(s) without the board skipped, %zu rejected\n", floor,
              fit.views_used - floor, detected.skipped, fit.rejected_views.size());
  for (std::size_t i = 0; i < fit.rejected_views.size(); ++i) {
    std::printf("  rejected %s: %s\n",
                detected.files[static_cast<std::size_t>(fit.rejected_views[i])].c_str(),
                fit.view_errors[i].c_str());
  }
  std::printf("corners: %d used, %d dropped as outliers; rms residual %.3f px", fit.corners, fit.outliers,
              fit.rms_px);
  if (std::isfinite(fit.rim_rms_sigma)) std::printf("; rim circles %.2f sigma", fit.rim_rms_sigma);
  std::printf("\n\n| parameter | value | 1 sigma |\n|---|---|---|\n");
  std::printf("| centre u | %.3f px | %.3f px |\n| centre v | %.3f px | %.3f px |\n", c.center_u_px,
              s[calib::kCenterU], c.center_v_px, s[calib::kCenterV]);
  std::printf("| focal scale | %.5f | %.5f (%.3f%%) |\n", c.rig.focal_scale, s[calib::kFocalScale],
              100.0 * s[calib::kFocalScale]);
  std::printf("| mirror dz | %.3f mm | %.3f mm |\n", c.rig.mirror_dz_mm, s[calib::kMirrorDz]);
  std::printf("| mirror tilt x | %.4f deg | %.4f deg |\n| mirror tilt y | %.4f deg | %.4f deg |\n",
              c.rig.mirror_tilt_x_rad * kDeg, s[calib::kTiltX] * kDeg, c.rig.mirror_tilt_y_rad * kDeg,
              s[calib::kTiltY] * kDeg);
  std::printf("| mirror offset x | %.3f mm | %.3f mm |\n| mirror offset y | %.3f mm | %.3f mm |\n",
              c.rig.mirror_offset_x_mm, s[calib::kOffsetX], c.rig.mirror_offset_y_mm, s[calib::kOffsetY]);
  const char *held = fit.level_fitted ? "" : " (held)";
  std::printf("| level tilt x | %.4f deg | %.4f deg%s |\n| level tilt y | %.4f deg | %.4f deg%s |\n",
              c.rig.level_tilt_x_rad * kDeg, s[calib::kLevelX] * kDeg, held, c.rig.level_tilt_y_rad * kDeg,
              s[calib::kLevelY] * kDeg, held);
  if (std::isfinite(fit.camera_height_m))
    std::printf("| camera height | %.4f m | %.4f m |\n", fit.camera_height_m, fit.camera_height_sigma_m);
  if (std::isfinite(fit.level_chi2)) {
    std::printf("level tilt: fitting it takes %.1f off the chi-square (%s, Akaike: 4 for its 2 parameters)\n",
                fit.level_chi2, fit.level_fitted ? "fitted" : "held at the configured tilt");
  }
  const calib::RangeUncertainty range =
      calib::range_uncertainty(fit.camera, fit.covariance, config.scan.camera_height_m);
  std::printf(
      "\nrange error these uncertainties imply, wall base on the floor at 1 / 2 / 4 m (1 sigma):\n"
      "  floor plane %.1f / %.1f / %.1f mm, stereo %.1f / %.1f / %.1f mm\n",
      range.floor_plane_m[0] * 1e3, range.floor_plane_m[1] * 1e3, range.floor_plane_m[2] * 1e3,
      range.stereo_m[0] * 1e3, range.stereo_m[1] * 1e3, range.stereo_m[2] * 1e3);
}

void write_yaml(const std::string &file, const calib::TargetFitResult &fit) {
  const mirror::MirrorConfig &c = fit.camera;
  const auto &s = fit.sigma;
  std::ofstream out(file);
  char text[512];
  std::snprintf(
      text, sizeof text,
      "# omnislam calibrate target: %d views, %d corners, rms %.3f px; 1 sigma: centre %.3f %.3f px, "
      "focal_scale %.5f, mirror_dz_mm %.3f, tilt %.4f %.4f deg, offset %.3f %.3f mm, level tilt %.4f %.4f "
      "deg\n",
      fit.views_used, fit.corners, fit.rms_px, s[calib::kCenterU], s[calib::kCenterV], s[calib::kFocalScale],
      s[calib::kMirrorDz], s[calib::kTiltX] * kDeg, s[calib::kTiltY] * kDeg, s[calib::kOffsetX],
      s[calib::kOffsetY], s[calib::kLevelX] * kDeg, s[calib::kLevelY] * kDeg);
  out << text;
  if (std::isfinite(fit.camera_height_m)) {
    std::snprintf(text, sizeof text,
                  "# camera height above the floor (boards on it): %.4f +- %.4f m; the rig above was fitted "
                  "with it, so it goes with them (a tape's height would scale every floor range)\n",
                  fit.camera_height_m, fit.camera_height_sigma_m);
    out << text;
  }
  std::snprintf(text, sizeof text,
                "camera: {center_px: [%.4f, %.4f], focal_scale: %.6f, mirror_dz_mm: %.4f, "
                "mirror_tilt_deg: [%.5f, %.5f], mirror_offset_mm: [%.4f, %.4f]",
                c.center_u_px, c.center_v_px, c.rig.focal_scale, c.rig.mirror_dz_mm,
                c.rig.mirror_tilt_x_rad * kDeg, c.rig.mirror_tilt_y_rad * kDeg, c.rig.mirror_offset_x_mm,
                c.rig.mirror_offset_y_mm);
  out << text;
  if (c.rig.level_tilt_x_rad != 0.0 || c.rig.level_tilt_y_rad != 0.0) {
    // Fitted from the boards on the floor, or (--hold-level) the configured one the fit was
    // made with: either way it goes with the rest.
    std::snprintf(text, sizeof text, ", level_tilt_deg: [%.5f, %.5f]", c.rig.level_tilt_x_rad * kDeg,
                  c.rig.level_tilt_y_rad * kDeg);
    out << text;
  }
  if (std::isfinite(fit.camera_height_m)) {
    std::snprintf(text, sizeof text, ", camera_height_m: %.4f", fit.camera_height_m);
    out << text;
  }
  out << "}\n";
  if (!out) throw std::runtime_error(file + ": cannot write");
}

void run_target(const TargetOptions &options) {
  const auto start = std::chrono::steady_clock::now();
  const io::Config config = options.config.empty() ? io::Config{} : io::load_config(options.config);
  const mirror::MirrorConfig &camera = config.scan.camera;
  const calib::TargetGeometry target = geometry_of(options);
  const Detected detected = detect(options, camera, target);
  if (static_cast<int>(detected.views.size()) < kMinViews) {
    throw std::runtime_error("the board was found in " + std::to_string(detected.views.size()) + " of " +
                             std::to_string(options.images.size()) + " image(s); need at least " +
                             std::to_string(kMinViews) + "; nothing written");
  }
  calib::TargetFitConfig fit_config;
  fit_config.floor_height_m = config.scan.camera_height_m;
  fit_config.fit_level = !options.hold_level;
  const calib::TargetFitResult fit =
      calib::fit_target(camera, target, detected.views, detected.rim, fit_config);
  if (!fit.converged || !std::isfinite(fit.sigma[calib::kCenterU])) {
    throw std::runtime_error("the fit failed: " + fit.message + "; nothing written");
  }
  print_report(fit, detected, config);
  if (!std::isfinite(fit.camera_height_m)) {
    throw std::runtime_error(
        "no board lay on the floor (level, about camera_height_m below the camera): without one the image "
        "centre is not determined (docs/calibration.md); nothing written");
  }
  write_yaml(options.out, fit);
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s (%.1f s)\n", options.out.c_str(), elapsed_s);
}

}  // namespace

void add_calibrate_target(CLI::App &calibrate) {
  auto *command = calibrate.add_subcommand(
      "target",
      "every rig parameter from images of a printed chessboard held round the robot and laid on the floor");
  auto options = std::make_shared<TargetOptions>();
  command->add_option("IMAGE", options->images, "8-bit images of the rig, each showing the board once")
      ->required();
  command->add_option("--config", options->config, "YAML configuration (camera: the start; camera_height_m)");
  command->add_option("--squares", options->squares, "squares across and down the board (default 8x6)");
  command->add_option("--square-mm", options->square_mm,
                      "side of a square as printed, measured (default 45)");
  command->add_flag(
      "--hold-level", options->hold_level,
      "keep the configured camera.level_tilt_deg (e.g. from an inclinometer) instead of fitting it "
      "from the boards on the floor");
  command->add_option("--out", options->out, "YAML file to write (camera: centre and rig keys)")->required();
  command->callback([options] { run_target(*options); });
}

}  // namespace omnislam::app
