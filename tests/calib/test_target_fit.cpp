#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "omnislam/calib/target_fit.hpp"

using omnislam::calib::RimCircles;
using omnislam::calib::TargetFitResult;
using omnislam::calib::TargetGeometry;
using omnislam::calib::TargetView;
using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorConfig;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A rig at the acceptance limits: the centre 5 px off, focal and distance ~1%,
// tilt up to 1 deg, offset up to 1 mm.
MirrorConfig true_rig() {
  MirrorConfig config;
  config.center_u_px = 515.1;
  config.center_v_px = 508.3;
  config.rig.focal_scale = 1.0095;
  config.rig.mirror_dz_mm = -2.6;
  config.rig.mirror_tilt_x_rad = 0.95 * kDeg;
  config.rig.mirror_tilt_y_rad = -0.7 * kDeg;
  config.rig.mirror_offset_x_mm = 0.9;
  config.rig.mirror_offset_y_mm = -1.0;
  return config;
}

// A board held by someone walking round the robot: its centre ~0.8 m from the axis and
// 0.3-0.7 m below the camera, facing the axis and leaning back to face the mirror, turned a
// little about its normal. T_camera_board.
Eigen::Isometry3d held_board(const TargetGeometry &target, double azimuth_rad, std::mt19937 &random) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double range_m = 0.8 + 0.15 * uniform(random);
  const double height_m = -0.5 + 0.2 * uniform(random);
  const double lean_rad = (35.0 + 15.0 * uniform(random)) * kDeg;
  const double roll_rad = 20.0 * kDeg * uniform(random);
  const Eigen::Vector3d radial(std::cos(azimuth_rad), std::sin(azimuth_rad), 0.0);
  const Eigen::Vector3d tangential(-std::sin(azimuth_rad), std::cos(azimuth_rad), 0.0);
  // The board's z points away from the camera; its x runs along the tangent, turned by roll.
  const Eigen::Vector3d z = (radial * std::cos(lean_rad) - Eigen::Vector3d::UnitZ() * std::sin(lean_rad));
  const Eigen::Vector3d x = Eigen::AngleAxisd(roll_rad, z) * tangential;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  const Eigen::Vector3d half(target.corners_x() - 1, target.corners_y() - 1, 0.0);
  T.translation() =
      range_m * radial + height_m * Eigen::Vector3d::UnitZ() - T.linear() * half * target.square_m / 2.0;
  return T;
}

// A board lying on the floor 1 m below the camera, its centre 0.8-1.2 m from the axis,
// turned any way about the vertical. T_camera_board.
Eigen::Isometry3d floor_board(const TargetGeometry &target, double azimuth_rad, std::mt19937 &random) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double range_m = 1.0 + 0.2 * uniform(random);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(std::numbers::pi * uniform(random), Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Vector3d half(target.corners_x() - 1, target.corners_y() - 1, 0.0);
  T.translation() = Eigen::Vector3d(range_m * std::cos(azimuth_rad), range_m * std::sin(azimuth_rad), -1.0) -
                    T.linear() * half * target.square_m / 2.0;
  return T;
}

// The views of `held` boards held around the robot and `on_floor` boards lying around it,
// through `rig_config`, corners with pixel noise, only those the lobes really see (2 px in
// from each lobe's edges).
std::vector<TargetView> observe(const MirrorConfig &rig_config, const TargetGeometry &target, int held,
                                int on_floor, double noise_px, unsigned seed) {
  const omnislam::mirror::RigModel rig(rig_config);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<TargetView> views;
  for (int i = 0; i < held + on_floor; ++i) {
    const bool floor = i >= held;
    const double azimuth_rad =
        2.0 * std::numbers::pi * (floor ? (i - held + 0.7) / on_floor : (i + 0.3) / held);
    const Eigen::Isometry3d T =
        floor ? floor_board(target, azimuth_rad, random) : held_board(target, azimuth_rad, random);
    TargetView view;
    view.on_floor = floor;
    for (int index = 0; index < target.corners(); ++index) {
      for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
        const auto pixel = rig.project(lobe, T * target.corner_m(index));
        if (!pixel || !rig.sees_lobe(lobe, *pixel, 2.0)) continue;
        view.corners.push_back({index, lobe, {pixel->u_px + noise(random), pixel->v_px + noise(random)}});
      }
    }
    views.push_back(view);
  }
  return views;
}

// The rim circles where `rig_config` puts them, off by `error_px` (the rim method's
// accuracy on renders: within 0.05 px), with the circle fit's own small sigma.
RimCircles rim_of(const MirrorConfig &rig_config, const Eigen::Vector2d &error_px) {
  const auto predicted = omnislam::calib::predict_rim(rig_config);
  omnislam::calib::CircleFit rim, central;
  rim.centre_px = predicted.rim_centre_px + error_px;
  central.centre_px = predicted.central_centre_px - error_px;
  rim.radius_px = predicted.rim_radius_px;
  central.radius_px = predicted.central_radius_px;
  rim.centre_sigma_px = central.centre_sigma_px = Eigen::Vector2d(0.01, 0.01);
  return {rim, central};
}

std::array<double, omnislam::calib::kRigParameters> errors_of(const TargetFitResult &fit,
                                                              const MirrorConfig &truth) {
  const auto &rig = fit.camera.rig;
  return {fit.camera.center_u_px - truth.center_u_px,
          fit.camera.center_v_px - truth.center_v_px,
          rig.focal_scale - truth.rig.focal_scale,
          rig.mirror_dz_mm - truth.rig.mirror_dz_mm,
          rig.mirror_tilt_x_rad - truth.rig.mirror_tilt_x_rad,
          rig.mirror_tilt_y_rad - truth.rig.mirror_tilt_y_rad,
          rig.mirror_offset_x_mm - truth.rig.mirror_offset_x_mm,
          rig.mirror_offset_y_mm - truth.rig.mirror_offset_y_mm};
}

}  // namespace

// The acceptance, measured (8 boards held round the robot and 16 laid on the floor,
// 24 images, corners with 0.1 px noise, the rim circles 0.03 px off): what holds and what
// does not.
//   parameter   error            sigma           acceptance
//   centre      -1.17 / 0.95 px  0.96 / 0.94 px  0.1 px      does NOT hold
//   focal       0.068%           0.051%          0.05%       does not hold (1.3 sigma)
//   distance    0.37 mm (0.14%)  0.28 mm         0.1%        does not hold (1.3 sigma)
//   tilt        0.015 / 0.018 d  0.015 deg       0.05 deg    holds
//   offset      0.09 / -0.07 mm  0.07 mm
// Why the centre cannot: target_fit.hpp (a centre shift is, to first order, a turn of the
// camera against mirror and world together; only the floor's flatness and the pinhole's
// perspective tell them apart). 12 held boards alone: centre sigma ~5 px; with the rim and
// 6 boards on the floor 1.6 px. The fit's sigmas say so honestly: each error is within 4
// sigma of its own.
TEST_CASE("target fit: a misaligned rig from boards held and laid on the floor, poses unknown",
          "[calib][target][slow]") {
  const MirrorConfig truth = true_rig();
  const TargetGeometry target;  // 8 x 6 squares of 45 mm: an A3 sheet
  const std::vector<TargetView> views = observe(truth, target, 8, 16, 0.1, 3);
  const TargetFitResult fit =
      omnislam::calib::fit_target(MirrorConfig{}, target, views, rim_of(truth, {0.03, -0.03}));
  INFO(fit.message);
  REQUIRE(fit.converged);
  CHECK(fit.views_used == 24);
  CHECK(fit.outliers == 0);
  CHECK(fit.rms_px == Approx(0.1).epsilon(0.2));  // the noise put in
  CHECK(fit.camera_height_m == Approx(1.0).margin(4.0 * fit.camera_height_sigma_m));
  const auto errors = errors_of(fit, truth);
  for (int i = 0; i < omnislam::calib::kRigParameters; ++i) {
    CAPTURE(i, errors[i], fit.sigma[i]);
    CHECK(std::isfinite(fit.sigma[i]));
    CHECK(std::abs(errors[i]) < 4.0 * fit.sigma[i]);
  }
  using namespace omnislam::calib;
  // Acceptance lines that hold.
  CHECK(std::abs(errors[kTiltX]) < 0.05 * kDeg);
  CHECK(std::abs(errors[kTiltY]) < 0.05 * kDeg);
  // The lines that do not, at what was measured (see above): not the numbers.
  CHECK(std::abs(errors[kCenterU]) < 1.5);
  CHECK(std::abs(errors[kCenterV]) < 1.5);
  CHECK(fit.sigma[kCenterU] < 1.2);
  CHECK(std::abs(errors[kFocalScale]) < 1e-3);
  CHECK(std::abs(errors[kMirrorDz]) < 0.5);
  // The rig is square to the floor: its level tilt is kept only where it is worth its two
  // parameters (Akaike: chi-square down by more than 4, which chance alone does in e^-2 =
  // 14% of fits; here 0.45, held).
  CAPTURE(fit.level_chi2);
  CHECK(fit.level_fitted == (fit.level_chi2 > 4.0));
  CHECK_FALSE(fit.level_fitted);
  CHECK(fit.camera.rig.level_tilt_x_rad == 0.0);
  CHECK(fit.sigma[kLevelX] == 0.0);
}

TEST_CASE("target fit: without boards on the floor the centre is weak, and the rim does not fix it",
          "[calib][target]") {
  const MirrorConfig truth = true_rig();
  const TargetGeometry target;
  const std::vector<TargetView> views = observe(truth, target, 16, 0, 0.1, 3);
  const TargetFitResult fit =
      omnislam::calib::fit_target(MirrorConfig{}, target, views, rim_of(truth, {0.0, 0.0}));
  INFO(fit.message);
  REQUIRE(fit.converged);
  CAPTURE(fit.sigma[omnislam::calib::kCenterU], fit.sigma[omnislam::calib::kCenterV]);
  CHECK(fit.sigma[omnislam::calib::kCenterU] > 3.0);  // measured 4.6 px
  CHECK(std::isnan(fit.camera_height_m));
}

TEST_CASE("target fit: too few views, a view without inner-lobe corners, a wrong corner", "[calib][target]") {
  const MirrorConfig truth = true_rig();
  const TargetGeometry target;
  std::vector<TargetView> views = observe(truth, target, 4, 2, 0.05, 5);
  const RimCircles rim = rim_of(truth, {0.0, 0.0});

  const std::vector<TargetView> one(views.begin(), views.begin() + 1);
  const TargetFitResult single = omnislam::calib::fit_target(MirrorConfig{}, target, one, rim);
  CHECK_FALSE(single.converged);
  CHECK_THAT(single.message, Catch::Contains("too few usable views"));

  std::vector<TargetView> with_bad = views;
  TargetView outer_only;
  for (const auto &corner : views[0].corners)
    if (corner.lobe == Lobe::kOuter) outer_only.corners.push_back(corner);
  with_bad.push_back(outer_only);
  with_bad[1].corners[3].pixel.u_px += 6.0;  // a corner on the neighbouring square
  const TargetFitResult fit = omnislam::calib::fit_target(MirrorConfig{}, target, with_bad, rim);
  INFO(fit.message);
  REQUIRE(fit.converged);
  CHECK(fit.views_used == 6);
  REQUIRE(fit.rejected_views == std::vector<int>{6});
  CHECK_THAT(fit.view_errors[0], Catch::Contains("0 corner(s) in the inner lobe"));
  CHECK(fit.outliers == 1);
  CHECK(fit.rms_px < 0.08);
}

namespace {

// The worst floor-range error over 16 azimuths at `range_m` when `fitted` (with its camera
// height) reads the pixels at which `truth` images a wall's base on the floor 1 m below.
double worst_floor_range_error_m(const TargetFitResult &fitted, const MirrorConfig &truth, double range_m) {
  const omnislam::mirror::RigModel imaging(truth), reading(fitted.camera);
  double worst = 0.0;
  for (int a = 0; a < 16; ++a) {
    const double phi = 2.0 * std::numbers::pi * a / 16.0;
    const auto pixel =
        imaging.project(Lobe::kInner, {range_m * std::cos(phi), range_m * std::sin(phi), -1.0});
    REQUIRE(pixel);
    const auto ray = reading.back_project(Lobe::kInner, *pixel);
    REQUIRE(ray);
    const double t = (-fitted.camera_height_m - ray->origin_m.z()) / ray->direction.z();
    worst = std::max(worst, std::abs((ray->origin_m + t * ray->direction).head<2>().norm() - range_m));
  }
  return worst;
}

}  // namespace

// The whole rig 0.8 / -0.6 deg off level (a mount not square to the floor): the boards on
// the floor show the floor's normal in the camera frame, so the fit finds the tilt (held
// level instead, it finds an equivalent rig, the centre tens of pixels off, whose floor
// ranges are bent). Measured (8 held, 12 on the floor, seed 3): tilt errors -0.10 / -0.06
// deg, sigma 0.07 deg; worst floor-range error at 2 m 3.0 mm, against 74 mm for the true rig
// read as level. (The square rig's test above: the tilt held.)
TEST_CASE("target fit: a rig off level is found from the boards on the floor", "[calib][target][slow]") {
  MirrorConfig truth = true_rig();
  truth.rig.level_tilt_x_rad = 0.8 * kDeg;
  truth.rig.level_tilt_y_rad = -0.6 * kDeg;
  const TargetGeometry target;
  const std::vector<TargetView> views = observe(truth, target, 8, 12, 0.1, 3);
  const RimCircles rim = rim_of(truth, {0.03, -0.03});
  const TargetFitResult fit = omnislam::calib::fit_target(MirrorConfig{}, target, views, rim);
  INFO(fit.message);
  REQUIRE(fit.converged);
  CHECK(fit.level_fitted);
  CHECK(fit.level_chi2 > 4.0);
  using omnislam::calib::kLevelX;
  using omnislam::calib::kLevelY;
  const double error_x = fit.camera.rig.level_tilt_x_rad - truth.rig.level_tilt_x_rad;
  const double error_y = fit.camera.rig.level_tilt_y_rad - truth.rig.level_tilt_y_rad;
  CAPTURE(error_x / kDeg, error_y / kDeg, fit.sigma[kLevelX] / kDeg, fit.sigma[kLevelY] / kDeg);
  CHECK(std::abs(error_x) < 4.0 * fit.sigma[kLevelX]);
  CHECK(std::abs(error_y) < 4.0 * fit.sigma[kLevelY]);
  CHECK(std::abs(error_x) < 0.15 * kDeg);
  CHECK(std::abs(error_y) < 0.15 * kDeg);

  // Held at the configured level (none), by request: the tilt is not touched (a few boards
  // are enough to show it).
  omnislam::calib::TargetFitConfig held;
  held.fit_level = false;
  const std::vector<TargetView> few(views.begin() + 4, views.begin() + 12);
  const TargetFitResult level = omnislam::calib::fit_target(MirrorConfig{}, target, few, rim, held);
  CHECK_FALSE(level.level_fitted);
  CHECK(level.camera.rig.level_tilt_x_rad == 0.0);
  CHECK(std::isnan(level.level_chi2));
  // What the tilt is worth: the floor ranges of the fitted rig against those of the true rig
  // read as level.
  TargetFitResult read_level;
  read_level.camera = truth;
  read_level.camera.rig.level_tilt_x_rad = read_level.camera.rig.level_tilt_y_rad = 0.0;
  read_level.camera_height_m = 1.0;
  const double fitted_error_m = worst_floor_range_error_m(fit, truth, 2.0);
  const double level_error_m = worst_floor_range_error_m(read_level, truth, 2.0);
  CAPTURE(fitted_error_m, level_error_m);
  CHECK(fitted_error_m < 0.008);
  CHECK(level_error_m > 4.0 * fitted_error_m);
}
