#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>

#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/planar_pose.hpp"
#include "omnislam/slam/ray_agreement.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

// A kidnapped robot (slam::SlamConfig::lost_after_frames): lifted, pushed or towed to another
// place while its odometry reports (nearly) no motion. Tracking must notice that the scans no
// longer fit the map, keep the map clean, find the robot on its map and go on from there.

using omnislam::slam::Slam;
using omnislam::slam::SlamConfig;
using omnislam::test::Segment;

namespace {

double distance_to_walls(const std::vector<Segment> &walls, const Eigen::Vector2d &p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Segment &s : walls) {
    const Eigen::Vector2d e = s.b - s.a;
    const double t = std::clamp((p - s.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (s.a + t * e - p).norm());
  }
  return best;
}

// A tour of l_room() that maps the room, then is carried (at frame `at`, after the tour) to
// where frame `to` of the tour was and drives on from there to the tour's end.
struct Kidnap {
  std::vector<Eigen::Isometry2d> truth;
  std::vector<Eigen::Isometry2d> odometry;  // blind to the carrying
  std::size_t at = 0;                       // the first frame after the carrying
};

Kidnap kidnapped_tour(std::size_t to, std::uint64_t seed) {
  const std::vector<Eigen::Isometry2d> tour = omnislam::test::laps_along(omnislam::test::l_room_tour(), 1);
  Kidnap k;
  k.truth = tour;
  k.at = tour.size();
  // What the wheels report: the tour, then (no motion while carried) the rest of the tour
  // from `to` on, composed onto the tour's last pose.
  std::vector<Eigen::Isometry2d> felt = tour;
  for (std::size_t i = to; i < tour.size(); ++i) {
    k.truth.push_back(tour[i]);
    felt.push_back(tour.back() * tour[to].inverse() * tour[i]);
  }
  k.odometry = omnislam::slam::apply_thesis_odometry_noise(felt, seed);
  return k;
}

struct KidnapRun {
  int first_lost = -1;  // frame the tracking was first reported lost at
  int found = -1;       // frame it was found again at
  int lost_frames = 0;
  int mapped_while_lost = 0;       // frames lost or not fitting the map that were integrated
  double worst_map_point_m = 0.0;  // of the final map, from the walls
  double found_error_m = 0.0;      // of the frame it was found at
  double worst_after_found_m = 0.0;
  double worst_final_since_carried_m = 0.0;  // of the final trajectory, from the carrying on
};

KidnapRun run_kidnap(const SlamConfig &config, const Kidnap &k, std::uint64_t seed) {
  const std::vector<Segment> walls = omnislam::test::l_room();
  std::mt19937_64 rng(seed);
  Slam slam(config);
  KidnapRun r;
  for (std::size_t i = 0; i < k.truth.size(); ++i) {
    const auto estimate = slam.process(omnislam::test::scan_from(walls, k.truth[i], rng), k.odometry[i]);
    const double error_m = (estimate.T_map_base.translation() - k.truth[i].translation()).norm();
    if (estimate.lost) {
      ++r.lost_frames;
      if (r.first_lost < 0) r.first_lost = static_cast<int>(i);
    }
    if (estimate.mapped && (estimate.lost || i >= k.at) && r.found < 0) ++r.mapped_while_lost;
    if (estimate.relocalized && i >= k.at && r.found < 0) {
      r.found = static_cast<int>(i);
      r.found_error_m = error_m;
    }
    if (r.found >= 0) r.worst_after_found_m = std::max(r.worst_after_found_m, error_m);
    if (std::getenv("OMNISLAM_TRACE"))
      std::printf("%zu err %.3f int %d mapped %d lost %d found %d att %d rms %.4f inl %.2f\n", i, error_m,
                  estimate.integrated, estimate.mapped, estimate.lost, estimate.relocalized,
                  static_cast<int>(estimate.attempt), std::sqrt(estimate.registration.final_error_m2),
                  estimate.registration.inlier_share);
  }
  for (const auto &p : slam.map().points())
    r.worst_map_point_m = std::max(r.worst_map_point_m, distance_to_walls(walls, p.position_m));
  const std::vector<Eigen::Isometry2d> final_poses = slam.trajectory();
  for (std::size_t i = k.at; i < final_poses.size(); ++i) {
    r.worst_final_since_carried_m = std::max(
        r.worst_final_since_carried_m, (final_poses[i].translation() - k.truth[i].translation()).norm());
  }
  return r;
}

}  // namespace

TEST_CASE("SLAM: a robot carried to another mapped place is lost, found on its map, and the map stays clean",
          "[slam][kidnap]") {
  // Tour frames 12 (along the first leg) and 40 (back along the long side, facing the other
  // way): 2.4 and 2.7 m from where the tour ends.
  for (std::size_t to : {std::size_t{12}, std::size_t{40}}) {
    for (std::uint64_t seed : {1u, 2u}) {
      const Kidnap k = kidnapped_tour(to, seed);
      const KidnapRun r = run_kidnap(SlamConfig{}, k, seed);
      INFO("carried to tour frame " << to << ", seed " << seed << ": lost at " << r.first_lost
                                    << " (carried at " << k.at << "), found at " << r.found << " with "
                                    << r.found_error_m << " m, worst after " << r.worst_after_found_m
                                    << " m, " << r.mapped_while_lost << " mapped while lost, worst map point "
                                    << r.worst_map_point_m << " m, worst final pose since the carrying "
                                    << r.worst_final_since_carried_m << " m");
      // Never lost before the carrying; after it, found by the search the first misfit
      // starts (three frames to confirm a pose), before or soon after being declared lost.
      CHECK((r.first_lost < 0 || r.first_lost >= static_cast<int>(k.at)));
      REQUIRE(r.found >= static_cast<int>(k.at));
      CHECK(r.found <= static_cast<int>(k.at) + SlamConfig{}.lost_after_frames + 4);
      CHECK(r.found_error_m < 0.05);
      CHECK(r.worst_after_found_m < 0.08);
      // In the final trajectory the frames between the carrying and the confirmation are
      // placed back from the found pose by their odometry (dead-reckoned from before the
      // carrying they were metres off).
      CHECK(r.worst_final_since_carried_m < 0.1);
      // Nothing seen from the wrong pose reached the map.
      CHECK(r.mapped_while_lost == 0);
      CHECK(r.worst_map_point_m < 0.1);
    }
  }
}

TEST_CASE("SLAM: without lost detection the same carrying writes the scans into the map at the wrong pose",
          "[slam][kidnap]") {
  // What lost_after_frames prevents (the test above would not notice if the carrying were
  // harmless): a scan that fits the previous scan but not the map is integrated, and the map
  // holds walls where there are none.
  SlamConfig config;
  config.lost_after_frames = 0;
  const Kidnap k = kidnapped_tour(40, 1);
  const KidnapRun r = run_kidnap(config, k, 1);
  INFO("worst map point " << r.worst_map_point_m << " m, mapped after the carrying " << r.mapped_while_lost);
  CHECK(r.first_lost < 0);
  CHECK(r.found < 0);
  CHECK(r.worst_map_point_m > 0.5);
}

TEST_CASE("SLAM: a scan that does not fit the map for a frame or two is not mapped and the track holds",
          "[slam][kidnap]") {
  // Someone stepping in front of the camera: two frames whose scans show a close wall of
  // legs, not the room. Neither is integrated, the robot is never lost, tracking goes on.
  const std::vector<Segment> walls = omnislam::test::l_room();
  const std::vector<Eigen::Isometry2d> truth = omnislam::test::laps_along(omnislam::test::l_room_tour(), 1);
  const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, 3);
  std::mt19937_64 rng(3);
  Slam slam;
  double worst_m = 0.0;
  int lost = 0, mapped_blocked = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    omnislam::slam::Points2 scan = omnislam::test::scan_from(walls, truth[i], rng);
    const bool blocked = i == 20 || i == 21;
    if (blocked) {
      // A ring of clutter 0.5-0.8 m around the robot on every side.
      scan.clear();
      std::uniform_real_distribution<double> range(0.5, 0.8);
      for (int deg = 0; deg < 360; deg += 2) {
        const double a = deg * std::numbers::pi / 180.0, r = range(rng);
        scan.emplace_back(r * std::cos(a), r * std::sin(a));
      }
    }
    const auto estimate = slam.process(scan, odometry[i]);
    lost += estimate.lost ? 1 : 0;
    mapped_blocked += blocked && estimate.mapped ? 1 : 0;
    if (!blocked)
      worst_m = std::max(worst_m, (estimate.T_map_base.translation() - truth[i].translation()).norm());
  }
  double worst_map_point_m = 0.0;
  for (const auto &p : slam.map().points())
    worst_map_point_m = std::max(worst_map_point_m, distance_to_walls(walls, p.position_m));
  INFO("worst " << worst_m << " m, worst map point " << worst_map_point_m << " m");
  CHECK(lost == 0);
  CHECK(mapped_blocked == 0);
  CHECK(worst_m < 0.05);
  CHECK(worst_map_point_m < 0.1);
}

TEST_CASE("ray agreement: a scan agrees with itself, crosses a map seen from elsewhere, sees new territory",
          "[slam][kidnap]") {
  using omnislam::slam::ray_agreement;
  const std::vector<Segment> walls = omnislam::test::l_room();
  std::mt19937_64 rng(7);
  const Eigen::Isometry2d here = omnislam::test::pose(1.0, 0.0, 0.3);
  const omnislam::slam::Points2 scan = omnislam::test::scan_from(walls, here, rng);
  const omnislam::slam::Points2 map = omnislam::slam::transformed(scan, here);
  // The same scan where it was taken: every point on the structure.
  const auto same = ray_agreement(scan, here, map, 0.1, 0.025);
  CHECK(same.confirmed > static_cast<int>(0.95 * scan.size()));
  CHECK_FALSE(same.contradicts(0.1));
  // The scan taken 2.2 m away (at (3, 1), between the boxes) placed here: many of its rays
  // reach farther than the walls this place's scan met, crossing them.
  const Eigen::Isometry2d there = omnislam::test::pose(3.0, 1.0, 0.3);
  const omnislam::slam::Points2 elsewhere = omnislam::test::scan_from(walls, there, rng);
  const auto wrong = ray_agreement(elsewhere, here, map, 0.1, 0.025);
  INFO("wrong place: confirmed " << wrong.confirmed << ", seen through " << wrong.seen_through << ", unseen "
                                 << wrong.unseen);
  CHECK(wrong.contradicts(0.1));
  // An empty map: everything is new territory, nothing contradicts.
  const auto fresh = ray_agreement(scan, here, omnislam::slam::Points2{}, 0.1, 0.025);
  CHECK(fresh.unseen == static_cast<int>(scan.size()));
  CHECK_FALSE(fresh.contradicts(0.1));
}

namespace {

// What a front-end shows on a hard floor (a high-contrast checkerboard, a dark skirting on
// dark tiles): of every scan a share of points in the free floor short of the wall (texture
// taken for an obstacle) and a share some 0.2 m beyond it (a skirting's top taken for the
// wall's base), different points in every frame.
omnislam::slam::Points2 scan_with_wrong_points(const std::vector<Segment> &walls, const Eigen::Isometry2d &T,
                                               std::mt19937_64 &rng, double short_share, double long_share) {
  omnislam::slam::Points2 scan = omnislam::test::scan_from(walls, T, rng);
  std::uniform_real_distribution<double> u(0.0, 1.0), fraction(0.3, 0.9);
  for (auto &p : scan) {
    const double draw = u(rng);
    if (draw < short_share) {
      p *= fraction(rng);
    } else if (draw < short_share + long_share) {
      p *= (p.norm() + 0.2) / p.norm();
    }
  }
  return scan;
}

}  // namespace

TEST_CASE(
    "SLAM: scans that disagree with each other more than the bundled floors' do are not taken for a carrying",
    "[slam][kidnap]") {
  // Measured on a held-out checkerboard room: consecutive scans at their true poses crossed
  // each other's structure with 16-24% of their points, against the relocaliser's 10%
  // outlier share; every frame from the fourth on was judged a misfit, the robot lost for
  // good on the frames of a room it was mapping (max error 821 mm; 19 mm never judged). The
  // misfit test now judges by how much this run's scans disagree where the map places them.
  const std::vector<Segment> walls = omnislam::test::l_room();
  const std::vector<Eigen::Isometry2d> truth = omnislam::test::laps_along(omnislam::test::l_room_tour(), 1);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, seed);
    std::mt19937_64 rng(seed);
    Slam slam;
    int lost = 0, not_mapped = 0;
    double worst_m = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const auto estimate =
          slam.process(scan_with_wrong_points(walls, truth[i], rng, 0.12, 0.08), odometry[i]);
      lost += estimate.lost ? 1 : 0;
      not_mapped += estimate.integrated ? 0 : 1;
      worst_m = std::max(worst_m, (estimate.T_map_base.translation() - truth[i].translation()).norm());
    }
    INFO("seed " << seed << ": lost " << lost << " frames, not integrated " << not_mapped << ", worst "
                 << worst_m << " m");
    CHECK(lost == 0);
    CHECK(worst_m < 0.06);
  }
}

TEST_CASE("SLAM: with scans that disagree more, a carrying is still noticed and kept out of the map",
          "[slam][kidnap]") {
  // The tolerance grows with the run's own disagreement, not to a scan from elsewhere.
  const Kidnap k = kidnapped_tour(40, 1);
  const std::vector<Segment> walls = omnislam::test::l_room();
  std::mt19937_64 rng(1);
  Slam slam;
  int in_doubt_after = 0, mapped_after = 0, lost_before = 0;
  for (std::size_t i = 0; i < k.truth.size(); ++i) {
    const auto estimate =
        slam.process(scan_with_wrong_points(walls, k.truth[i], rng, 0.12, 0.08), k.odometry[i]);
    if (i < k.at) {
      lost_before += estimate.lost ? 1 : 0;
    } else if (i < k.at + 3) {
      in_doubt_after += estimate.mapped ? 0 : 1;
      mapped_after +=
          estimate.mapped && (estimate.T_map_base.translation() - k.truth[i].translation()).norm() > 0.2;
    }
  }
  double worst_map_point_m = 0.0;
  for (const auto &p : slam.map().points())
    worst_map_point_m = std::max(worst_map_point_m, distance_to_walls(walls, p.position_m));
  INFO("lost before the carrying " << lost_before << ", not mapped in the 3 frames after it "
                                   << in_doubt_after << ", mapped at a wrong pose " << mapped_after
                                   << ", worst map point " << worst_map_point_m << " m");
  CHECK(lost_before == 0);
  CHECK(in_doubt_after == 3);
  CHECK(mapped_after == 0);
}

namespace {

// Two 4 x 4 m rooms side by side (x 0..4 and 4..8, y 0..4), alike down to a box in the same
// corner of each, joined by a 1 m door (y 1.5..2.5) in the wall between them: a room the map
// has never seen that looks like one it has.
std::vector<Segment> twin_rooms(bool door_open) {
  std::vector<Segment> walls;
  for (const double x0 : {0.0, 4.0}) {
    walls.push_back({{x0, 0}, {x0 + 4, 0}});
    walls.push_back({{x0, 4}, {x0 + 4, 4}});
    walls.push_back({{x0 + 0.6, 2.9}, {x0 + 1.2, 2.9}});  // the box
    walls.push_back({{x0 + 1.2, 2.9}, {x0 + 1.2, 3.4}});
    walls.push_back({{x0 + 1.2, 3.4}, {x0 + 0.6, 3.4}});
    walls.push_back({{x0 + 0.6, 3.4}, {x0 + 0.6, 2.9}});
  }
  walls.push_back({{0, 0}, {0, 4}});
  walls.push_back({{8, 0}, {8, 4}});
  walls.push_back({{4, 0}, {4, 1.5}});
  walls.push_back({{4, 2.5}, {4, 4}});
  if (!door_open) walls.push_back({{4, 1.5}, {4, 2.5}});
  return walls;
}

}  // namespace

TEST_CASE("SLAM: lost in a doorway to an unmapped room that looks like a mapped one, it is not found there",
          "[slam][kidnap]") {
  // The robot maps the first room with the door shut; then the door is open and it drives
  // through into the second room, which the first room explains perfectly 4 m away. A map
  // registration that rejects a frame with a tenth of its points off the map stands in for
  // a front-end whose points through a doorway are poor (a realistic building's lap with
  // scans out to 8 m was lost at a door and confirmed 14 m off, in a corridor like the one it
  // was in): the robot is in doubt in the doorway, then lost. Every scan still fits the one
  // before it where the odometry puts it: the robot was not carried, it is where dead
  // reckoning took it, and the search keeps to that. Searching the whole map confirmed the
  // look-alike pose in every seed (12 of 12 measured).
  std::vector<Eigen::Isometry2d> truth =
      omnislam::test::laps_along({{1, 1}, {3, 1}, {3, 2}, {1, 2}, {1, 1}}, 2);
  const std::size_t mapped_frames = truth.size();
  for (const Eigen::Isometry2d &p :
       omnislam::test::laps_along({{1, 2}, {6, 2}, {6, 1.4}, {6.6, 1.4}, {1, 2}}, 1)) {
    if (p.translation().x() > 6.5) break;  // into the second room and round its middle
    truth.push_back(p);
  }
  SlamConfig config;
  config.min_inlier_share = 0.9;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, seed);
    std::mt19937_64 rng(seed);
    Slam slam(config);
    int lost = 0, wrong = 0;
    double worst_m = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const auto estimate =
          slam.process(omnislam::test::scan_from(twin_rooms(i >= mapped_frames), truth[i], rng), odometry[i]);
      // The map's frame is the first pose's.
      const double error_m =
          (estimate.T_map_base.translation() - (truth.front().inverse() * truth[i]).translation()).norm();
      lost += estimate.lost ? 1 : 0;
      if (!estimate.lost) worst_m = std::max(worst_m, error_m);
      wrong += !estimate.lost && error_m > 1.0 ? 1 : 0;
    }
    INFO("seed " << seed << ": " << lost << " frames lost, " << wrong << " frames placed over 1 m off, worst "
                 << worst_m << " m");
    CHECK(lost > 0);
    CHECK(wrong == 0);
    CHECK(worst_m < 0.5);
  }
}
