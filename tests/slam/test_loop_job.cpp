#include <catch2/catch.hpp>

#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "omnislam/slam/loop_job.hpp"
#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

// Loop closure handed out as a job (background mode), run and given back some frames later,
// against the same loop closure run inline at each keyframe.

using namespace omnislam::slam;
using omnislam::test::pose;

namespace {

// Laps of the L-room along its corridor-like legs, 0.2 m steps.
std::vector<Eigen::Isometry2d> l_room_laps(int laps) {
  return omnislam::test::laps_along(omnislam::test::l_room_tour(), laps);
}

SlamConfig background() {
  SlamConfig config;
  config.loop_closure.background = true;
  return config;
}

struct Run {
  std::vector<FrameEstimate> online;
  std::vector<Eigen::Isometry2d> truth;
  int loop_closures = 0;
  int jobs = 0;
  int catch_up_jobs = 0;
  int maps_checked = 0;  ///< maps compared with one rebuilt from the adopted graph
  double online_final_m = 0.0;
  double optimised_final_m = 0.0;
  double optimised_max_m = 0.0;
  double worst_scale_error = 0.0;  ///< max |det(R) - 1| of the online poses' rotations
};

// Frames through `slam`; in background mode each job is run `delay` frames after it was
// taken and its result applied before the next frame (delay 0: before the very next frame).
Run run(Slam &slam, const std::vector<Eigen::Isometry2d> &truth, std::uint64_t seed, int delay) {
  const auto odometry = apply_thesis_odometry_noise(truth, seed);
  std::mt19937_64 rng(seed);
  Run out;
  std::optional<LoopJob> out_job;
  int held = 0;
  std::optional<std::vector<MapPoint>> map_after_apply, map_of_graph;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (out_job && held++ >= delay) {
      const std::vector<Eigen::Isometry2d> before = slam.trajectory();
      const KeyframeGraph &copy = out_job->catch_up ? *out_job->catch_up->solved : out_job->graph;
      const std::size_t copied = copy.keyframes().size();
      // The keyframe the live pose is tracked against: the job's newest (or one made since,
      // which moves with it), or an older one being revisited.
      const int anchor = slam.keyframes().anchor_keyframe();
      const std::size_t follows = anchor >= 0 && static_cast<std::size_t>(anchor) + 1 < copied
                                      ? static_cast<std::size_t>(anchor)
                                      : copied - 1;
      const Eigen::Isometry2d followed_before =
          copied > 0 ? slam.keyframes().keyframes()[follows].T_map_keyframe : Eigen::Isometry2d::Identity();
      const int closures = slam.loop_closures();
      slam.apply_loop_result(run_loop_job(std::move(*out_job)));
      out_job.reset();
      if (slam.loop_closures() > closures) {
        // The live pose (the last frame's, on the graph) moved with that keyframe.
        const Eigen::Isometry2d correction =
            slam.keyframes().keyframes()[follows].T_map_keyframe * followed_before.inverse();
        const Eigen::Isometry2d expected = correction * before.back();
        CHECK((slam.trajectory().back().translation() - expected.translation()).norm() < 1e-9);
        map_after_apply = slam.map().points();
        map_of_graph = slam.keyframes().rebuilt_map(PointMapConfig{}, {}, 0).points();
      }
    }
    const FrameEstimate estimate =
        slam.process(omnislam::test::scan_from(omnislam::test::l_room(), truth[i], rng), odometry[i]);
    if (estimate.map_rebuilt && map_after_apply) {
      // The map rebuilt on the worker and caught up with the frames tracked meanwhile is the
      // map of the adopted graph, point for point.
      REQUIRE(map_after_apply->size() == map_of_graph->size());
      bool same = true;
      for (std::size_t p = 0; p < map_of_graph->size(); ++p)
        same = same && (*map_after_apply)[p].position_m == (*map_of_graph)[p].position_m &&
               (*map_after_apply)[p].hits == (*map_of_graph)[p].hits;
      CHECK(same);
      ++out.maps_checked;
    }
    map_after_apply.reset();
    out.worst_scale_error =
        std::max(out.worst_scale_error, std::abs(estimate.T_map_base.linear().determinant() - 1.0));
    out.online.push_back(estimate);
    out.truth.push_back(truth.front().inverse() * truth[i]);
    if (!out_job) {
      out_job = slam.take_loop_job();
      held = 0;
      if (out_job) ++(out_job->catch_up ? out.catch_up_jobs : out.jobs);
    }
  }
  while (out_job) {  // the end of the run: the job out still lands
    slam.apply_loop_result(run_loop_job(std::move(*out_job)));
    out_job = slam.take_loop_job();
    if (out_job) ++(out_job->catch_up ? out.catch_up_jobs : out.jobs);
  }
  out.loop_closures = slam.loop_closures();
  const auto optimised = slam.trajectory();
  REQUIRE(optimised.size() == truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i)
    out.optimised_max_m =
        std::max(out.optimised_max_m, (optimised[i].translation() - out.truth[i].translation()).norm());
  out.optimised_final_m = (optimised.back().translation() - out.truth.back().translation()).norm();
  out.online_final_m = (out.online.back().T_map_base.translation() - out.truth.back().translation()).norm();
  return out;
}

}  // namespace

TEST_CASE("loop job: results applied before the next frame give the inline run's closures and accuracy",
          "[slam][loop]") {
  const auto truth = l_room_laps(2);
  for (std::uint64_t seed : {1u, 2u}) {
    Slam inline_slam;
    Slam handed_out(background());
    const Run a = run(inline_slam, truth, seed, 0);
    const Run b = run(handed_out, truth, seed, 0);
    INFO("seed " << seed << ": inline " << a.loop_closures << " closures, optimised max " << a.optimised_max_m
                 << " m; handed out " << b.loop_closures << " closures in " << b.jobs
                 << " jobs, optimised max " << b.optimised_max_m << " m, online final " << b.online_final_m
                 << " m");
    CHECK(a.jobs == 0);  // inline: nothing is handed out
    CHECK(b.jobs > 0);
    CHECK(b.loop_closures == a.loop_closures);
    CHECK(b.loop_closures > 0);
    CHECK(std::abs(b.optimised_max_m - a.optimised_max_m) < 0.002);
    CHECK(b.optimised_max_m < 0.05);
  }
}

TEST_CASE("loop job: many corrections leave the live pose a rotation", "[slam][loop]") {
  // A correction is the newest keyframe's optimised pose times the inverse of its tracked
  // pose, and Isometry2d::inverse() transposes: applied to the live pose again and again it
  // squared the rotation's rounding error each time (after ~50 closures the pose was scaled
  // by 0.98 and the run 2 m off on a looped room; planar_pose.hpp orthonormalized()).
  // Keyframes on every lap (no revisits), so that every lap closes loops.
  const auto truth = l_room_laps(4);
  SlamConfig config = background();
  config.loop_closure.reuse_keyframes = false;
  Slam slam(config);
  const Run r = run(slam, truth, 4, 0);
  INFO(r.loop_closures << " closures, worst |det - 1| " << r.worst_scale_error << ", optimised max "
                       << r.optimised_max_m << " m");
  CHECK(r.loop_closures >= 25);
  CHECK(r.worst_scale_error < 1e-12);
  for (const Keyframe &keyframe : slam.keyframes().keyframes())
    CHECK(std::abs(keyframe.T_map_keyframe.linear().determinant() - 1.0) < 1e-12);
  CHECK(r.optimised_max_m < 0.05);
}

TEST_CASE("loop job: a result given back frames later still corrects the live pose", "[slam][loop]") {
  const auto truth = l_room_laps(2);
  SlamConfig without;
  without.loop_closure.enabled = false;
  // Every correction rebuilds the map, so the map caught up on the "worker" is checked too.
  SlamConfig config = background();
  config.loop_closure.rebuild_min_shift_m = 0.0;
  for (int delay : {3, 8}) {
    Slam slam(config);
    Slam open(without);
    const Run late = run(slam, truth, 1, delay);
    const Run tracking = run(open, truth, 1, 0);
    INFO("delay " << delay << " frames: " << late.loop_closures << " closures, " << late.jobs << " jobs, "
                  << late.catch_up_jobs << " catch-up jobs, " << late.maps_checked
                  << " rebuilt maps checked; optimised max " << late.optimised_max_m << " m, final "
                  << late.optimised_final_m << " m, online final " << late.online_final_m
                  << " m; without loop closure: max " << tracking.optimised_max_m << " m");
    CHECK(late.loop_closures > 0);
    CHECK(late.catch_up_jobs > 0);  // the maps lagged by more than max_catch_up_scans
    CHECK(late.maps_checked > 0);
    CHECK(late.optimised_max_m < 0.05);
    CHECK(late.optimised_max_m <= tracking.optimised_max_m + 0.01);
    // The correction reached the live pose (issue 13: online final within 1.5x of the optimised).
    CHECK(late.online_final_m <= std::max(1.5 * late.optimised_final_m, late.optimised_final_m + 0.005));
    CHECK_FALSE(slam.loop_job_out());
  }
}

TEST_CASE("loop job: one out at a time, the keyframes made meanwhile searched as the newest",
          "[slam][loop]") {
  const auto truth = l_room_laps(1);
  const auto odometry = apply_thesis_odometry_noise(truth, 3);
  std::mt19937_64 rng(3);
  Slam slam(background());
  std::optional<LoopJob> out;
  int searched = -1;  // the newest keyframe the last job searched
  int keyframes_while_out = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const FrameEstimate estimate =
        slam.process(omnislam::test::scan_from(omnislam::test::l_room(), truth[i], rng), odometry[i]);
    if (out) {
      keyframes_while_out += estimate.keyframe ? 1 : 0;
      CHECK_FALSE(slam.take_loop_job());  // never a second one
      if (keyframes_while_out == 3) {     // a slow worker: three keyframes later
        slam.apply_loop_result(run_loop_job(std::move(*out)));
        out.reset();
        CHECK_FALSE(slam.loop_job_out());
      }
      continue;
    }
    out = slam.take_loop_job();
    // Every keyframe but the first (nothing to search yet) hands one out.
    CHECK(static_cast<bool>(out) == ((estimate.keyframe && i > 0) || keyframes_while_out > 0));
    if (out) {
      const int newest = out->graph.last();
      CHECK(newest == slam.keyframes().last());
      CHECK(newest > searched);
      searched = newest;
      keyframes_while_out = 0;
      CHECK(slam.loop_job_out());
      // The job shares the stored scans instead of copying them.
      CHECK(out->graph.keyframes().front().scans_keyframe.front() ==
            slam.keyframes().keyframes().front().scans_keyframe.front());
    }
  }
  CHECK(searched > 0);
}

TEST_CASE("loop job: a result from before a resume is ignored", "[slam][loop]") {
  const auto truth = l_room_laps(1);
  std::mt19937_64 rng(4);
  Slam slam(background());
  std::optional<LoopJob> out;
  for (std::size_t i = 0; i < 6 && !out; ++i) {
    (void)slam.process(omnislam::test::scan_from(omnislam::test::l_room(), truth[i], rng), truth[i]);
    out = slam.take_loop_job();
  }
  REQUIRE(out);
  const std::vector<MapPoint> saved = slam.map().points();
  slam.resume(saved, slam.map().integrations(), truth[5], Eigen::Matrix3d::Identity() * 1e-4, truth[5]);
  CHECK_FALSE(slam.loop_job_out());
  const std::size_t keyframes = slam.keyframes().keyframes().size();
  slam.apply_loop_result(run_loop_job(std::move(*out)));
  CHECK(slam.keyframes().keyframes().size() == keyframes);
  CHECK(slam.map().points().size() == saved.size());
  CHECK_FALSE(slam.loop_job_out());
  // The next keyframe hands out a job again.
  (void)slam.process(omnislam::test::scan_from(omnislam::test::l_room(), truth[6], rng), truth[6]);
  CHECK(slam.take_loop_job());
}
