#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "omnislam/calib/level_fit.hpp"
#include "omnislam/mirror/rig_model.hpp"

using omnislam::calib::FloorContact;
using omnislam::calib::LevelFitResult;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Floor contacts 0.5-4 m round a rig turned (tilt_x, tilt_y) off level, 1.0 m above the
// floor, as the rig sees them (its frame): per frame 150 wall bases with `noise_m` of height
// error, one height error shared by the frame's contacts (`frame_error_m`), and a tenth of
// them a skirting board's top 8 cm up.
std::vector<FloorContact> contacts_of(double tilt_x, double tilt_y, int frames, double noise_m,
                                      double frame_error_m, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> azimuth(0.0, 2.0 * std::numbers::pi), range(0.5, 4.0),
      unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_m), shared(0.0, frame_error_m);
  const Eigen::Matrix3d camera_from_level = omnislam::mirror::tilt_rotation(tilt_x, tilt_y).transpose();
  std::vector<FloorContact> contacts;
  for (int frame = 0; frame < frames; ++frame) {
    const double offset = shared(random);
    for (int i = 0; i < 150; ++i) {
      const double a = azimuth(random), r = range(random);
      const double height = unit(random) < 0.1 ? 0.08 : 0.0;
      Eigen::Vector3d p =
          camera_from_level * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), -1.0 + height);
      p.z() += noise(random) + offset;
      contacts.push_back({p, frame});
    }
  }
  return contacts;
}

}  // namespace

TEST_CASE("level fit: the floor plane's tilt and depth from contacts round a rig off level",
          "[calib][level]") {
  const std::vector<FloorContact> contacts = contacts_of(0.8 * kDeg, -0.6 * kDeg, 20, 0.012, 0.002, 7);
  const LevelFitResult fit = omnislam::calib::fit_level(contacts);
  INFO(fit.message);
  REQUIRE(fit.ok);
  CHECK(fit.frames == 20);
  CHECK(fit.contacts == 3000);
  // The skirting tops (8 cm = 6.7 robust scales up) weigh nothing.
  CHECK(fit.inliers < 2800);
  CHECK(fit.residual_scale_m == Approx(0.012).epsilon(0.2));
  const double sx = std::sqrt(fit.covariance(1, 1)), sy = std::sqrt(fit.covariance(2, 2));
  CAPTURE(fit.tilt_x_rad / kDeg, fit.tilt_y_rad / kDeg, sx / kDeg, sy / kDeg, fit.floor_z_m);
  CHECK(std::abs(fit.tilt_x_rad - 0.8 * kDeg) < 4.0 * sx);
  CHECK(std::abs(fit.tilt_y_rad + 0.6 * kDeg) < 4.0 * sy);
  CHECK(std::abs(fit.tilt_x_rad - 0.8 * kDeg) < 0.02 * kDeg);
  CHECK(std::abs(fit.tilt_y_rad + 0.6 * kDeg) < 0.02 * kDeg);
  CHECK(fit.floor_z_m == Approx(-1.0).margin(4.0 * std::sqrt(fit.covariance(0, 0))));
}

TEST_CASE("level fit: the uncertainty is the frames', not the contacts'", "[calib][level]") {
  // Each frame's contacts share a height error of 5 mm: a thousand points do not average it
  // away, the frames do. Over 40 draws the tilt's errors fall within the stated sigma as a
  // Gaussian's would (a t with 19 dof: ~68% within 1 sigma, more with the sandwich's own
  // noise), not a few times outside.
  int inside = 0, draws = 40;
  for (int draw = 0; draw < draws; ++draw) {
    const LevelFitResult fit =
        omnislam::calib::fit_level(contacts_of(0.3 * kDeg, 0.2 * kDeg, 20, 0.010, 0.005, 100 + draw));
    REQUIRE(fit.ok);
    const double sx = std::sqrt(fit.covariance(1, 1));
    if (std::abs(fit.tilt_x_rad - 0.3 * kDeg) < sx) ++inside;
  }
  CAPTURE(inside);
  CHECK(inside >= 20);
}

TEST_CASE("level fit: too few contacts or frames are said, not fitted", "[calib][level]") {
  const std::vector<FloorContact> contacts = contacts_of(0.0, 0.0, 2, 0.01, 0.0, 3);
  const LevelFitResult fit = omnislam::calib::fit_level(contacts);
  CHECK_FALSE(fit.ok);
  CHECK_THAT(fit.message, Catch::Contains("300 floor contact(s) in 2 image(s); need 30 in 3"));
}

TEST_CASE("level fit: composing tilts is the rotations' product", "[calib][level]") {
  const Eigen::Vector2d configured(0.5 * kDeg, -0.3 * kDeg), residual(0.2 * kDeg, 0.1 * kDeg);
  const Eigen::Vector2d composed = omnislam::calib::compose_level_tilt(configured, residual);
  const Eigen::Matrix3d product = omnislam::mirror::tilt_rotation(residual.x(), residual.y()) *
                                  omnislam::mirror::tilt_rotation(configured.x(), configured.y());
  // The composed pair turns the axis as the product does (a turn about the axis itself is
  // not a tilt).
  const Eigen::Vector3d axis =
      omnislam::mirror::tilt_rotation(composed.x(), composed.y()).transpose() * Eigen::Vector3d::UnitZ();
  CHECK((axis - product.transpose() * Eigen::Vector3d::UnitZ()).norm() < 1e-9);
  CHECK(composed.x() == Approx(0.7 * kDeg).epsilon(0.01));
  CHECK(composed.y() == Approx(-0.2 * kDeg).epsilon(0.02));
  CHECK((omnislam::calib::compose_level_tilt(configured, Eigen::Vector2d::Zero()) - configured).norm() <
        1e-12);
}
