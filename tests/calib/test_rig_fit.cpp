#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "omnislam/calib/rig_fit.hpp"

using omnislam::calib::RigObservation;
using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorConfig;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A rig at the acceptance limits.
MirrorConfig true_rig() {
  MirrorConfig config;
  config.center_u_px = 515.2;
  config.center_v_px = 508.9;
  config.rig.focal_scale = 0.992;
  config.rig.mirror_dz_mm = -2.7;
  config.rig.mirror_tilt_x_rad = 0.9 * kDeg;
  config.rig.mirror_tilt_y_rad = -0.6 * kDeg;
  config.rig.mirror_offset_x_mm = 0.8;
  config.rig.mirror_offset_y_mm = -1.0;
  return config;
}

// Points of a target seen around the robot: squares on the floor (1 m below) and on a
// board held upright, every 15 degrees, projected through the true rig with pixel noise.
std::vector<RigObservation> observe(const MirrorConfig &rig_config, double noise_px, unsigned seed) {
  const omnislam::mirror::RigModel rig(rig_config);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<RigObservation> observations;
  for (double azimuth_deg = 0.0; azimuth_deg < 360.0; azimuth_deg += 15.0) {
    const double phi = azimuth_deg * kDeg;
    for (double range_m : {0.7, 1.0, 1.5}) {
      for (double height_m : {-1.0, -0.7, -0.4}) {
        const Eigen::Vector3d point(range_m * std::cos(phi), range_m * std::sin(phi), height_m);
        for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
          const auto pixel = rig.project(lobe, point);
          if (!pixel || !rig.sees_lobe(lobe, *pixel)) continue;
          observations.push_back({lobe, point, {pixel->u_px + noise(random), pixel->v_px + noise(random)}});
        }
      }
    }
  }
  return observations;
}

}  // namespace

TEST_CASE("rig fit: recovers a misaligned rig from a target's points", "[calib][rig]") {
  const MirrorConfig truth = true_rig();
  const std::vector<RigObservation> observations = observe(truth, 0.1, 7);
  REQUIRE(observations.size() > 200u);
  const omnislam::calib::RigFitResult fit = omnislam::calib::fit_rig(MirrorConfig{}, observations);
  INFO(fit.message);
  REQUIRE(fit.converged);
  CHECK(fit.rms_px == Approx(0.1).epsilon(0.2));  // the noise put in
  const auto &rig = fit.camera.rig;
  // The acceptance for focal (0.05%), distance (0.1% of ~270 mm) and tilt (0.05 deg)
  // holds with a wide margin (measured sigmas: 0.009%, 0.030 mm, 0.005 deg; offset 0.025 mm).
  // The centre is not within its 0.1 px: sigma 0.34 px, since a centre shift is nearly a
  // rotation of the camera about the pinhole, which this target tells from a tilted and
  // offset mirror only weakly (the target method needs more: see the report).
  CHECK(std::abs(rig.focal_scale - truth.rig.focal_scale) < 5e-4);
  CHECK(std::abs(rig.mirror_dz_mm - truth.rig.mirror_dz_mm) < 0.27);
  CHECK(std::abs(rig.mirror_tilt_x_rad - truth.rig.mirror_tilt_x_rad) < 0.05 * kDeg);
  CHECK(std::abs(rig.mirror_tilt_y_rad - truth.rig.mirror_tilt_y_rad) < 0.05 * kDeg);
  CHECK(std::abs(rig.mirror_offset_x_mm - truth.rig.mirror_offset_x_mm) < 0.15);
  CHECK(std::abs(rig.mirror_offset_y_mm - truth.rig.mirror_offset_y_mm) < 0.15);
  // The reported uncertainties explain the errors (within 4 sigma) and are not vacuous.
  const double errors[] = {fit.camera.center_u_px - truth.center_u_px,
                           fit.camera.center_v_px - truth.center_v_px,
                           rig.focal_scale - truth.rig.focal_scale,
                           rig.mirror_dz_mm - truth.rig.mirror_dz_mm,
                           rig.mirror_tilt_x_rad - truth.rig.mirror_tilt_x_rad,
                           rig.mirror_tilt_y_rad - truth.rig.mirror_tilt_y_rad,
                           rig.mirror_offset_x_mm - truth.rig.mirror_offset_x_mm,
                           rig.mirror_offset_y_mm - truth.rig.mirror_offset_y_mm};
  for (int i = 0; i < omnislam::calib::kRigParameters; ++i) {
    CAPTURE(i, errors[i], fit.sigma[i]);
    CHECK(std::isfinite(fit.sigma[i]));
    CHECK(std::abs(errors[i]) < 4.0 * fit.sigma[i]);
  }
  CHECK(fit.sigma[omnislam::calib::kCenterU] < 0.5);
  CHECK(fit.sigma[omnislam::calib::kFocalScale] < 2e-4);
}

TEST_CASE("rig fit: too few observations are reported, not fitted", "[calib][rig]") {
  std::vector<RigObservation> observations = observe(true_rig(), 0.0, 1);
  observations.resize(10);
  const omnislam::calib::RigFitResult fit = omnislam::calib::fit_rig(MirrorConfig{}, observations);
  CHECK_FALSE(fit.converged);
  CHECK_THAT(fit.message, Catch::Contains("too few observations"));
}
