#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <utility>

#include "relocalization_run.hpp"

// Global relocalisation on the saved map of each bundled room: the robot starts at every
// frame in turn with no pose at all and must find it from its scans and odometry within
// ten frames, never reporting a wrong one (issue 13: >= 95% over >= 100 starts, within
// 50 mm and 1 deg, no wrong "localized"). Speed: tests/bench/bench_relocalize.

namespace {

std::filesystem::path dataset_dir(const char *name) {
  const char *root = std::getenv("OMNISLAM_DATASETS");
  return std::filesystem::path(root != nullptr ? root : OMNISLAM_DEFAULT_DATASETS) / name;
}

}  // namespace

TEST_CASE("relocalisation from every frame of the bundled rooms", "[slam][relocalize][dataset]") {
  int starts = 0, correct = 0, wrong = 0;
  for (const char *name : {"sim-room-37", "sim-room-turning", "l-room-1lap", "office-real"}) {
    INFO("dataset " << dataset_dir(name));
    REQUIRE(std::filesystem::is_regular_file(dataset_dir(name) / "dataset.yaml"));
    const auto run = omnislam::test::build_localization_run(dataset_dir(name));
    const auto outcome = omnislam::test::relocalize_from_every_frame(run, 10);
    std::printf("%s: %d starts, %d localized (%d correct, %d wrong), worst %.1f mm %.2f deg\n", name,
                outcome.starts, outcome.localized, outcome.correct, outcome.wrong,
                outcome.worst_error_m * 1000.0, outcome.worst_error_deg);
    starts += outcome.starts, correct += outcome.correct, wrong += outcome.wrong;
  }
  CHECK(starts >= 100);
  CHECK(wrong == 0);
  CHECK(correct >= 0.95 * starts);
}

// [slow]: 193 s under AddressSanitizer, which the rooms' case above covers the same code for.
TEST_CASE("relocalisation in building-2laps's corridors never reports a wrong pose",
          "[slam][relocalize][dataset][slow]") {
  // The stretches where the relocaliser once confirmed a wrong corridor: a corridor junction
  // 6.8 m away and turned 90 deg explained a few points more than the true pose (whose map
  // holds the two laps' walls ~0.15 m apart) for four frames, and the truth fell behind by
  // Wald's margin for one pair of poses while dozens competed (starts 75-85 and 260-275).
  // A start may stay unlocalized in a plain corridor, where ten frames cannot tell.
  REQUIRE(std::filesystem::is_regular_file(dataset_dir("building-2laps") / "dataset.yaml"));
  const auto run = omnislam::test::build_localization_run(dataset_dir("building-2laps"));
  int starts = 0, correct = 0, wrong = 0;
  for (const auto &[first, last] : {std::pair{70, 90}, std::pair{255, 280}}) {
    const auto outcome = omnislam::test::relocalize_from_frames(run, 10, first, last);
    starts += outcome.starts, correct += outcome.correct, wrong += outcome.wrong;
  }
  std::printf("building-2laps: %d starts, %d correct, %d wrong\n", starts, correct, wrong);
  CHECK(starts == 45);
  CHECK(wrong == 0);
  CHECK(correct > 0);
}
