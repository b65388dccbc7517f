#include <catch2/catch.hpp>

#include <chrono>
#include <cstdint>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "omnislam/pipeline/loop_closer.hpp"

// The background loop-closure worker: order, no job lost, clean shutdown with a job in
// flight (run under ThreadSanitizer with the other concurrency tests).

using namespace omnislam;
using namespace std::chrono_literals;

namespace {

// A job that takes a while: a catch-up of `scans` scans of a 4 x 4 m room into an empty map.
slam::LoopJob slow_job(const std::shared_ptr<const slam::Points2> &scan, int scans) {
  slam::LoopJob job;
  auto result = std::make_shared<slam::LoopResult>();
  result->map.emplace();
  job.catch_up = result;
  for (int i = 0; i < scans; ++i) {
    job.scans_since.push_back(
        {scan, Eigen::Isometry2d(Eigen::Translation2d(0.01 * i, 0.0) * Eigen::Rotation2Dd(0.001 * i))});
  }
  return job;
}

std::shared_ptr<const slam::Points2> room_scan() {
  slam::Points2 points;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> along(-2.0, 2.0);
  for (int i = 0; i < 400; ++i) {
    const double t = along(rng);
    const int wall = i % 4;
    points.emplace_back(wall == 0 ? -2.0 : wall == 1 ? 2.0 : t, wall == 2 ? -2.0 : wall == 3 ? 2.0 : t);
  }
  return std::make_shared<const slam::Points2>(std::move(points));
}

}  // namespace

TEST_CASE("loop closer: results come back in order, none lost (two threads, checksum)", "[pipeline]") {
  constexpr std::uint64_t kJobs = 300;
  pipeline::LoopCloser closer;
  std::vector<std::uint64_t> order;
  std::uint64_t checksum = 0;
  auto take = [&](std::optional<slam::LoopResult> result) {
    if (!result) return false;
    order.push_back(result->generation);
    checksum += result->generation * result->generation;
    return true;
  };
  for (std::uint64_t i = 0; i < kJobs; ++i) {
    slam::LoopJob job;  // an empty graph: nothing to search, done at once
    job.generation = i;
    closer.submit(std::move(job));
    while (take(closer.try_take())) {
    }
  }
  while (take(closer.wait_take())) {
  }
  REQUIRE(order.size() == kJobs);
  for (std::uint64_t i = 0; i < kJobs; ++i) CHECK(order[i] == i);
  CHECK(checksum == (kJobs - 1) * kJobs * (2 * kJobs - 1) / 6);
  CHECK(closer.jobs_done() == kJobs);
  CHECK_FALSE(closer.try_take());
  CHECK_FALSE(closer.wait_take());  // nothing submitted: returns at once
}

TEST_CASE("loop closer: a slow job's result is waited for, and integrates what it was given", "[pipeline]") {
  const auto scan = room_scan();
  pipeline::LoopCloser closer(19);
  closer.submit(slow_job(scan, 20));
  const std::optional<slam::LoopResult> result = closer.wait_take();
  REQUIRE(result);
  REQUIRE(result->map);
  CHECK(result->map->integrations() == 20);
  CHECK(result->map_integrations == 20);
  CHECK(result->catch_up_rounds == 1);
}

TEST_CASE("loop closer: destroyed with a job in flight and one queued, it joins and frees both",
          "[pipeline]") {
  const auto scan = room_scan();
  const auto begin = std::chrono::steady_clock::now();
  {
    pipeline::LoopCloser closer;
    closer.submit(slow_job(scan, 200));
    closer.submit(slow_job(scan, 200));
    std::this_thread::sleep_for(10ms);
    // The first job is being run: the destructor lets it finish and drops the second.
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  CHECK(scan.use_count() == 1);  // every job and result released its share of the scan
  INFO("joined after " << seconds << " s");
  CHECK(seconds < 60.0);
}
