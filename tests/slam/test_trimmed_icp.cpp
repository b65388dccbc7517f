#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "omnislam/slam/trimmed_icp.hpp"
#include "synthetic_room.hpp"

using omnislam::slam::NearestNeighbors;
using omnislam::slam::Points2;
using omnislam::slam::register_trimmed_icp;
using omnislam::slam::yaw_rad_of;
using omnislam::test::pose;

TEST_CASE("trimmed ICP recovers a known motion between two scans of a room", "[slam][icp]") {
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(7);
  const Eigen::Isometry2d T_map_a = pose(1.0, 0.5, 0.0);
  const Eigen::Isometry2d T_map_b = pose(1.25, 0.7, 0.06);
  const Points2 scan_a = omnislam::test::scan_from(walls, T_map_a, rng);
  const Points2 scan_b = omnislam::test::scan_from(walls, T_map_b, rng);
  const NearestNeighbors model(scan_a);
  const Eigen::Isometry2d truth = T_map_a.inverse() * T_map_b;  // T_a_b
  // Start 8 cm and 3 deg off, like a noisy odometry step.
  const Eigen::Isometry2d guess = truth * pose(0.06, -0.05, 0.05);
  const auto result = register_trimmed_icp(model, scan_b, guess);
  INFO("iterations " << result.iterations << " srel " << result.srel_percent << " rms "
                     << std::sqrt(result.final_error_m2) << " inliers " << result.inlier_share);
  REQUIRE(result.valid);
  const Eigen::Isometry2d error = truth.inverse() * result.T_model_sample;
  CHECK(error.translation().norm() < 0.01);
  CHECK(std::abs(yaw_rad_of(error)) < 0.2 * std::numbers::pi / 180.0);
  CHECK(std::sqrt(result.final_error_m2) < 0.02);
  CHECK(result.srel_percent > 50.0);
  CHECK(result.inlier_share > 0.8);
  CHECK(result.iterations <= 30);
  // The covariance is a small positive-definite matrix.
  CHECK(result.covariance.determinant() > 0.0);
  CHECK(result.covariance(0, 0) < 1e-4);
}

TEST_CASE("trimmed ICP: trimming ignores points the model does not contain", "[slam][icp]") {
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(11);
  const Points2 scan = omnislam::test::scan_from(walls, pose(1.0, 1.0, 0.0), rng, 0.005);
  Points2 sample;
  const Eigen::Isometry2d truth = pose(0.1, -0.05, 0.03);
  for (const auto &p : scan) sample.push_back(truth.inverse() * p);
  // 25% outliers: a clutter object only the sample sees.
  std::uniform_real_distribution<double> clutter(0.0, 0.6);
  for (std::size_t i = 0; i < scan.size() / 4; ++i)
    sample.emplace_back(2.0 + clutter(rng), -0.5 + clutter(rng));
  const auto result = register_trimmed_icp(NearestNeighbors(scan), sample, Eigen::Isometry2d::Identity());
  INFO("iterations " << result.iterations << " converged " << result.converged << " srel "
                     << result.srel_percent << " rms " << std::sqrt(result.final_error_m2));
  REQUIRE(result.valid);
  const Eigen::Isometry2d error = truth.inverse() * result.T_model_sample;
  CHECK(error.translation().norm() < 0.005);
  CHECK(std::abs(yaw_rad_of(error)) < 0.002);
}

TEST_CASE("trimmed ICP: thesis scale mode estimates a scale factor", "[slam][icp]") {
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(3);
  const Points2 model = omnislam::test::scan_from(walls, pose(1.0, 1.0, 0.0), rng, 0.0);
  Points2 sample;
  for (const auto &p : model) sample.push_back(p / 1.03);  // the sample is 3% short
  omnislam::slam::TrimmedIcpConfig config;
  config.metric = omnislam::slam::IcpMetric::kPointToPoint;
  config.estimate_scale = true;
  config.overlap = 0.95;
  const auto result =
      register_trimmed_icp(NearestNeighbors(model), sample, Eigen::Isometry2d::Identity(), config);
  REQUIRE(result.valid);
  CHECK(result.scale == Approx(1.03).margin(0.005));
}

TEST_CASE("trimmed ICP: degenerate inputs are reported invalid", "[slam][icp]") {
  const Points2 few = {{1.0, 0.0}, {0.0, 1.0}};
  const Eigen::Isometry2d guess = pose(0.3, 0.2, 0.1);
  auto result = register_trimmed_icp(NearestNeighbors(Points2{}), few, guess);
  CHECK_FALSE(result.valid);
  CHECK(result.T_model_sample.isApprox(guess));
  result = register_trimmed_icp(NearestNeighbors(few), few, guess);
  CHECK_FALSE(result.valid);
  // Sets too far apart for the search radius never pair up.
  const Points2 far = {{10, 10}, {11, 10}, {10, 11}, {11, 11}};
  const Points2 near = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  result = register_trimmed_icp(NearestNeighbors(far), near, Eigen::Isometry2d::Identity());
  CHECK_FALSE(result.valid);
}

TEST_CASE("trimmed ICP: a position prior holds the pose along a plain corridor, the walls fix the rest",
          "[slam][icp]") {
  // Two walls 2 m apart along x, seen 3 m each way; the robot moved 0.3 m along the corridor,
  // 5 cm sideways and turned 0.02 rad. Along x the walls say nothing (and trimming pulls the
  // scan back over the mapped stretch); the odometry said 0.3 m.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  auto corridor = [&](const Eigen::Isometry2d &T_map_base) {
    Points2 scan;
    for (double x = -3.0; x <= 3.0; x += 0.05) {
      for (const double y : {-1.0, 1.0}) {
        const Eigen::Vector2d map_point(T_map_base.translation().x() + x, y);
        scan.push_back(T_map_base.inverse() * map_point + Eigen::Vector2d(noise(rng), noise(rng)));
      }
    }
    return scan;
  };
  const NearestNeighbors model(corridor(pose(0.0, 0.0, 0.0)));
  const Eigen::Isometry2d truth = pose(0.3, 0.05, 0.02);
  const Points2 sample = corridor(truth);
  const Eigen::Isometry2d predicted = pose(0.3, 0.0, 0.0);
  omnislam::slam::PosePrior prior;
  prior.T_model_sample = predicted;
  prior.translation_covariance = Eigen::Matrix2d::Identity() * 0.0144 * 0.0144;  // 10% of 0.25 m / sqrt 3
  const auto held = register_trimmed_icp(model, sample, predicted, {}, &prior);
  REQUIRE(held.valid);
  const auto free = register_trimmed_icp(model, sample, predicted);
  INFO("with the prior x " << held.T_model_sample.translation().x() << ", without "
                           << free.T_model_sample.translation().x());
  CHECK(std::abs(held.T_model_sample.translation().x() - 0.3) < 0.01);
  CHECK(std::abs(held.T_model_sample.translation().y() - 0.05) < 0.005);
  CHECK(std::abs(yaw_rad_of(held.T_model_sample) - 0.02) < 0.002);
  CHECK(std::abs(free.T_model_sample.translation().x() - 0.3) > 0.05);  // slid along it without
  // Across the corridor the walls, not the prior, decide: the prior said y = 0.
  CHECK(std::abs(free.T_model_sample.translation().y() - 0.05) < 0.005);
}

TEST_CASE("trimmed ICP: along a corridor slightly bent walls do not overrule the prior", "[slam][icp]") {
  // The map of a plain corridor 2 m wide whose walls, from 1.5 m ahead, lean inward by 2 deg (a
  // front-end bends a wall seen obliquely; one scan's bend joins the map while the next scan
  // sees the wall straighter). Against their normals a shift along the corridor changes the
  // residuals by 3.5% of it, so the fit slides the scan along it to cancel millimetres across
  // it: the walls' millimetres divided by the lean. Those normals hold less than one pair's
  // worth of information along the corridor, so the prior keeps the position there, and the
  // covariance is the prior's.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.001);
  const double lean = std::tan(2.0 * std::numbers::pi / 180.0);
  Points2 map;
  for (double x = -3.0; x <= 3.3; x += 0.05) {
    const double inward = x > 1.5 ? (x - 1.5) * lean : 0.0;
    for (const double side : {-1.0, 1.0}) map.emplace_back(x, side * (1.0 - inward) + noise(rng));
  }
  const Eigen::Isometry2d truth = pose(0.3, 0.0, 0.0);
  Points2 sample;
  for (double x = -2.7; x <= 3.0; x += 0.05) {
    for (const double y : {-1.0, 1.0})
      sample.push_back(truth.inverse() * Eigen::Vector2d(0.3 + x, y + noise(rng)));
  }
  omnislam::slam::PosePrior prior;
  prior.T_model_sample = truth;
  const double sigma_m = 0.0144;  // 10% of a 0.25 m step / sqrt 3
  prior.translation_covariance = Eigen::Matrix2d::Identity() * sigma_m * sigma_m;
  omnislam::slam::TrimmedIcpConfig all_pairs;
  all_pairs.min_constraining_pairs = 0.0;  // the behaviour before: every direction the pairs'
  const auto held = register_trimmed_icp(NearestNeighbors(map), sample, truth, {}, &prior);
  const auto pulled = register_trimmed_icp(NearestNeighbors(map), sample, truth, all_pairs, &prior);
  REQUIRE(held.valid);
  REQUIRE(pulled.valid);
  INFO("x held " << held.T_model_sample.translation().x() << ", every direction the pairs' "
                 << pulled.T_model_sample.translation().x());
  CHECK(held.unconstrained_directions == 1);
  CHECK(pulled.unconstrained_directions == 0);
  CHECK(std::abs(held.T_model_sample.translation().x() - 0.3) < 0.001);
  CHECK(std::abs(pulled.T_model_sample.translation().x() - 0.3) > 0.005);  // 10.6 mm
  // Across the corridor and in heading the walls decide as before.
  CHECK(std::abs(held.T_model_sample.translation().y()) < 0.002);
  CHECK(std::abs(yaw_rad_of(held.T_model_sample)) < 0.001);
  // Along it the covariance is the prior's.
  CHECK(std::sqrt(held.robust_covariance(0, 0)) == Approx(sigma_m).epsilon(0.01));
  CHECK(std::sqrt(held.robust_covariance(1, 1)) < 0.002);
}

TEST_CASE("trimmed ICP: with walls along both directions the pairs decide every direction, prior or not",
          "[slam][icp]") {
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(13);
  const Eigen::Isometry2d T_map_a = pose(1.0, 0.5, 0.0), T_map_b = pose(1.25, 0.6, 0.03);
  const Points2 scan_a = omnislam::test::scan_from(walls, T_map_a, rng);
  const Points2 scan_b = omnislam::test::scan_from(walls, T_map_b, rng);
  const Eigen::Isometry2d truth = T_map_a.inverse() * T_map_b;
  omnislam::slam::PosePrior prior;
  prior.T_model_sample = truth * pose(0.02, -0.02, 0.0);
  prior.translation_covariance = Eigen::Matrix2d::Identity() * 0.0144 * 0.0144;
  omnislam::slam::TrimmedIcpConfig all_pairs;
  all_pairs.min_constraining_pairs = 0.0;
  const auto result =
      register_trimmed_icp(NearestNeighbors(scan_a), scan_b, prior.T_model_sample, {}, &prior);
  const auto before =
      register_trimmed_icp(NearestNeighbors(scan_a), scan_b, prior.T_model_sample, all_pairs, &prior);
  REQUIRE(result.valid);
  CHECK(result.unconstrained_directions == 0);
  CHECK((result.T_model_sample.matrix() - before.T_model_sample.matrix()).norm() ==
        Approx(0.0).margin(1e-12));
  CHECK((result.robust_covariance - before.robust_covariance).norm() == Approx(0.0).margin(1e-15));
  CHECK((truth.inverse() * result.T_model_sample).translation().norm() < 0.01);
}

TEST_CASE(
    "trimmed ICP: a prior of an exact odometry step (standing still) holds the position, the yaw is fitted",
    "[slam][icp]") {
  // Standing, the thesis odometry model gives a step with no translation variance. Its
  // inverse was infinite, the step undefined, and the registration returned where it
  // started, in yaw too: a heading 1.5 deg off stayed off for as long as the robot stood.
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(17);
  const Eigen::Isometry2d T_map = pose(1.0, 0.5, 0.2);
  const Points2 map = omnislam::test::scan_from(walls, T_map, rng);
  const Points2 scan = omnislam::test::scan_from(walls, T_map, rng);
  omnislam::slam::PosePrior prior;
  prior.T_model_sample = pose(0.0, 0.0, 1.5 * std::numbers::pi / 180.0);  // the truth is the identity
  prior.translation_covariance.setZero();
  const auto result = register_trimmed_icp(NearestNeighbors(map), scan, prior.T_model_sample, {}, &prior);
  REQUIRE(result.valid);
  INFO("yaw " << yaw_rad_of(result.T_model_sample) * 180.0 / std::numbers::pi << " deg, position "
              << result.T_model_sample.translation().transpose());
  CHECK(result.T_model_sample.matrix().allFinite());
  CHECK(std::abs(yaw_rad_of(result.T_model_sample)) < 0.1 * std::numbers::pi / 180.0);
  // The position stays within a few millimetres of the prior's (a millimetre's variance).
  CHECK(result.T_model_sample.translation().norm() < 0.005);
}

TEST_CASE("trimmed ICP: the cluster-robust covariance covers an error shared by a wall's points",
          "[slam][icp][covariance]") {
  // Two scans of the same room from the same place; in the sample every point beyond x > 2 m
  // (one wall seen from inside) reads 6 mm long, as a front-end's range bias on one surface
  // does. The independent-residual covariance takes the ~hundred points as a hundred
  // measurements; the pose error the bias causes lies far outside it, but within the
  // cluster-robust one, which is never smaller in any direction.
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(5);
  const Eigen::Isometry2d T_map_scan = pose(1.0, 1.0, 0.0);
  const Points2 model_scan = omnislam::test::scan_from(walls, T_map_scan, rng, 0.002);
  Points2 sample = omnislam::test::scan_from(walls, T_map_scan, rng, 0.002);
  for (auto &p : sample) {
    if ((T_map_scan * p).x() > 1.8) p *= 1.0 + 0.006 / p.norm();
  }
  const auto result =
      register_trimmed_icp(NearestNeighbors(model_scan), sample, Eigen::Isometry2d::Identity());
  REQUIRE(result.valid);
  const Eigen::Vector3d error(result.T_model_sample.translation().x(),
                              result.T_model_sample.translation().y(), yaw_rad_of(result.T_model_sample));
  const double nees_independent = error.dot(result.covariance.inverse() * error);
  const double nees_robust = error.dot(result.robust_covariance.inverse() * error);
  INFO("error " << error.transpose() << " NEES independent " << nees_independent << " robust "
                << nees_robust);
  CHECK(error.head<2>().norm() > 0.0005);  // the bias moved the fit
  CHECK(nees_independent > 16.27);         // outside the 99.9% region of the independent estimate
  CHECK(nees_robust < 16.27);              // inside the robust one's
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> difference(result.robust_covariance -
                                                                  result.covariance);
  CHECK(difference.eigenvalues().minCoeff() > -1e-15);
}

TEST_CASE("trimmed ICP: the robust covariance's degrees of freedom are its sectors less one",
          "[slam][icp][covariance]") {
  // A room seen all round fills every bearing sector: eight sectors give seven degrees of
  // freedom (their scores sum to zero at the fit). With one sector the independent estimate
  // stands in, with as many as the pairs less the three parameters.
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(6);
  const Eigen::Isometry2d T_map_scan = pose(1.0, 1.0, 0.0);
  const NearestNeighbors model(omnislam::test::scan_from(walls, T_map_scan, rng, 0.002));
  const Points2 sample = omnislam::test::scan_from(walls, T_map_scan, rng, 0.002);
  const auto sectors = register_trimmed_icp(model, sample, pose(0.02, -0.01, 0.01));
  REQUIRE(sectors.valid);
  CHECK(sectors.covariance_dof == 7.0);
  omnislam::slam::TrimmedIcpConfig independent;
  independent.covariance_sectors = 1;
  const auto pairs = register_trimmed_icp(model, sample, pose(0.02, -0.01, 0.01), independent);
  REQUIRE(pairs.valid);
  CHECK(pairs.covariance_dof == static_cast<double>(pairs.kept_pairs) - 3.0);
}

TEST_CASE("trimmed ICP: the predictive covariance is the t's, dof / (dof - 2) times the estimate",
          "[slam][icp][covariance]") {
  using omnislam::slam::predictive_covariance;
  const Eigen::Matrix3d estimate = Eigen::Vector3d(4e-6, 1e-6, 1e-5).asDiagonal();
  CHECK(predictive_covariance(estimate, 7.0).isApprox(estimate * 1.4));
  CHECK(predictive_covariance(estimate, 70.0).isApprox(estimate * 70.0 / 68.0));
  // A model's covariance (infinitely many degrees of freedom) is published as it is.
  CHECK(predictive_covariance(estimate, std::numeric_limits<double>::infinity()) == estimate);
  // Fewer than three would have no finite variance: three are assumed.
  CHECK(predictive_covariance(estimate, 1.0).isApprox(estimate * 3.0));
}

namespace {

// The scan pair the range-weighting tests draw: the L-room seen from two poses (the model with
// 2 mm of noise, up to 5 m), each sample point's range per pixel and read range given by
// `read(i, point, noise_px, rng)` with noise_px 0.3 px of image noise drawn for it.
struct RangedDraw {
  Points2 model;
  Points2 sample;
  std::vector<double> range_per_px;
};

const Eigen::Isometry2d &ranged_model_pose() {
  static const Eigen::Isometry2d T = pose(1.0, 1.0, 0.0);
  return T;
}
const Eigen::Isometry2d &ranged_sample_pose() {
  static const Eigen::Isometry2d T = pose(1.2, 0.9, 0.05);
  return T;
}

template <class Read>
RangedDraw ranged_draw(std::mt19937_64 &rng, Read read) {
  const auto walls = omnislam::test::l_room();
  RangedDraw draw{omnislam::test::scan_from(walls, ranged_model_pose(), rng, 0.002, 5.0),
                  omnislam::test::scan_from(walls, ranged_sample_pose(), rng, 0.0, 5.0),
                  {}};
  std::normal_distribution<double> pixels(0.0, 0.3);
  draw.range_per_px.resize(draw.sample.size());
  for (std::size_t i = 0; i < draw.sample.size(); ++i) {
    const double range_m = draw.sample[i].norm();
    const double noise_px = pixels(rng);
    const auto [range_per_px, read_m] = read(i, draw.sample[i], noise_px, rng);
    draw.range_per_px[i] = range_per_px;
    draw.sample[i] *= read_m / range_m;
  }
  return draw;
}

// The fit's position error against the true relative pose of the draw.
double position_error_m(const omnislam::slam::TrimmedIcpResult &fit) {
  const Eigen::Isometry2d truth = ranged_model_pose().inverse() * ranged_sample_pose();
  return (truth.inverse() * fit.T_model_sample).translation().norm();
}

// Where every fit of these tests starts: 36 mm and 0.6 deg off the truth.
Eigen::Isometry2d ranged_guess() {
  return ranged_model_pose().inverse() * ranged_sample_pose() * pose(0.03, -0.02, 0.01);
}

}  // namespace

TEST_CASE("trimmed ICP: points weighed by their range error per pixel outweigh the imprecise ones",
          "[slam][icp][weights]") {
  // A scan whose every second point is ranged by stereo (a short baseline: 0.25 m of range per
  // pixel, read 2% short, as table edges are) and the rest by the floor plane (range per pixel
  // growing with the square of the range); 0.3 px of image noise on every point. Told each
  // point's range per pixel, the registration fits the noise model to its own residuals and
  // the imprecise half no longer pulls the pose (plain 3.4 mm, weighted 1.1 mm here).
  double plain_error_m = 0.0, weighted_error_m = 0.0;
  constexpr int kTrials = 10;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::mt19937_64 rng(100 + trial);
    const RangedDraw draw =
        ranged_draw(rng, [](std::size_t i, const omnislam::slam::Point2 &point, double noise_px, auto &) {
          const double range_m = point.norm();
          const bool stereo = i % 2 == 0;
          const double range_per_px = stereo ? 0.25 : 0.005 * range_m * range_m;
          return std::pair{range_per_px, (stereo ? 0.98 * range_m : range_m) + range_per_px * noise_px};
        });
    const NearestNeighbors model(draw.model);
    const auto plain = register_trimmed_icp(model, draw.sample, ranged_guess());
    const auto weighted =
        register_trimmed_icp(model, draw.sample, ranged_guess(), {}, nullptr, draw.range_per_px);
    REQUIRE(plain.valid);
    REQUIRE(weighted.valid);
    CHECK(plain.range_noise_ratio == 0.0);
    CHECK(weighted.range_noise_ratio > 0.0);
    plain_error_m += position_error_m(plain) / kTrials;
    weighted_error_m += position_error_m(weighted) / kTrials;
  }
  INFO("mean position error: plain " << plain_error_m << " m, weighted " << weighted_error_m << " m");
  CHECK(weighted_error_m < 0.5 * plain_error_m);
  CHECK(weighted_error_m < 0.01);
}

TEST_CASE("trimmed ICP: a heavy-tailed residual law keeps a run of long floor contacts from pulling the pose",
          "[slam][icp][weights]") {
  // Every second point a floor contact (range per pixel growing with the square of the
  // range), the others stereo points (0.25 m per pixel); 0.3 px of image noise on all. Along
  // one stretch (~35 deg) the contacts are a skirting board's top: 8% long, and as precise by
  // their range per pixel as the true ones; a quarter of the other points are gross errors
  // (0.2-0.5 m short: floor texture, furniture), which the trimming takes first, so the run
  // is kept (measured: 20.6 mm Gaussian, 11.4 mm Student-t). The range weighting alone
  // trusts the run as much as the rest; the Student-t factor (residual_tail_dof 4) discounts
  // it by its residuals under the fitted model.
  omnislam::slam::TrimmedIcpConfig gaussian;
  gaussian.residual_tail_dof = 0.0;
  double gaussian_error_m = 0.0, tailed_error_m = 0.0;
  constexpr int kTrials = 10;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::mt19937_64 rng(200 + trial);
    const RangedDraw draw = ranged_draw(
        rng, [](std::size_t i, const omnislam::slam::Point2 &point, double noise_px, std::mt19937_64 &draws) {
          const double range_m = point.norm();
          const double bearing = std::atan2(point.y(), point.x());
          const bool skirting_top = i % 2 == 1 && bearing > 0.3 && bearing < 0.9;  // ~35 deg of walls
          const bool gross = !skirting_top && i % 4 == 1;
          const double range_per_px = i % 2 == 0 ? 0.25 : 0.005 * range_m * range_m;
          double read_m = (skirting_top ? 1.08 * range_m : range_m) + range_per_px * noise_px;
          if (gross) read_m -= 0.2 + 0.3 * std::uniform_real_distribution<double>(0.0, 1.0)(draws);
          return std::pair{range_per_px, read_m};
        });
    const NearestNeighbors model(draw.model);
    const auto without =
        register_trimmed_icp(model, draw.sample, ranged_guess(), gaussian, nullptr, draw.range_per_px);
    const auto with =
        register_trimmed_icp(model, draw.sample, ranged_guess(), {}, nullptr, draw.range_per_px);
    REQUIRE(without.valid);
    REQUIRE(with.valid);
    REQUIRE(with.range_noise_ratio > 0.0);
    gaussian_error_m += position_error_m(without) / kTrials;
    tailed_error_m += position_error_m(with) / kTrials;
  }
  INFO("mean position error: Gaussian " << gaussian_error_m << " m, Student-t " << tailed_error_m << " m");
  CHECK(tailed_error_m < 0.7 * gaussian_error_m);
}

TEST_CASE("trimmed ICP: no reweighting without range errors or with no passes", "[slam][icp][weights]") {
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(3);
  const Points2 model = omnislam::test::scan_from(walls, pose(1.0, 1.0, 0.0), rng, 0.005);
  const Points2 sample = omnislam::test::scan_from(walls, pose(1.1, 1.0, 0.02), rng, 0.005);
  const std::vector<double> range_per_px(sample.size(), 0.05);
  omnislam::slam::TrimmedIcpConfig no_passes;
  no_passes.range_weighting_passes = 0;
  const Eigen::Isometry2d guess = pose(0.1, 0.0, 0.02);
  const auto plain = register_trimmed_icp(NearestNeighbors(model), sample, guess);
  const auto unweighted =
      register_trimmed_icp(NearestNeighbors(model), sample, guess, no_passes, nullptr, range_per_px);
  CHECK(unweighted.range_noise_ratio == 0.0);
  CHECK(unweighted.T_model_sample.isApprox(plain.T_model_sample, 0.0));
  CHECK(unweighted.covariance.isApprox(plain.covariance, 0.0));
}
