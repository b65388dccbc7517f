// bench_relocalize [DATASET...]: global relocalisation on the saved map of each dataset (the
// map its replay builds), started at every frame with no pose: success, frames needed, and
// the time of each relocaliser frame (a search of the whole map, the refinement of every
// hypothesis) on one thread. Default: the bundled rooms.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <chrono>
#include <random>

#include "omnislam/slam/relocalizer.hpp"
#include "relocalization_run.hpp"
#include "synthetic_room.hpp"

namespace {

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1))];
}

// A building of side x side rooms (5 m, a door in every inner wall) with one box placed
// differently in every room; the map sampled every 2 cm; ten starts in different rooms,
// each driven forward with exact odometry and 6 m scans until localized.
void building_row(int side) {
  auto walls = omnislam::test::building(side);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> where(0.6, 3.8);
  for (int room = 0; room < side * side; ++room) {
    const double x0 = (room % side) * 5.0 + where(rng), y0 = (room / side) * 5.0 + where(rng);
    const std::vector<Eigen::Vector2d> box = {{x0, y0}, {x0 + 0.6, y0}, {x0 + 0.6, y0 + 0.4}, {x0, y0 + 0.4}};
    for (std::size_t i = 0; i < box.size(); ++i) walls.push_back({box[i], box[(i + 1) % box.size()]});
  }
  omnislam::slam::Points2 map;
  for (const auto &s : walls) {
    const int steps = std::max(1, static_cast<int>((s.b - s.a).norm() / 0.02));
    for (int i = 0; i <= steps; ++i) map.push_back(s.a + (s.b - s.a) * (static_cast<double>(i) / steps));
  }
  std::vector<double> frame_ms;
  int localized = 0, correct = 0, frames_needed = 0;
  std::uniform_int_distribution<int> pick_room(0, side * side - 1);
  std::uniform_real_distribution<double> yaw(-3.14, 3.14);
  for (int start = 0; start < 10; ++start) {
    const int room = pick_room(rng);
    Eigen::Isometry2d pose =
        omnislam::test::pose((room % side) * 5.0 + 1.5, (room / side) * 5.0 + 2.5, yaw(rng));
    omnislam::slam::Relocalizer relocalizer(map);
    for (int frame = 1; frame <= 10; ++frame) {
      const auto scan = omnislam::test::scan_from(walls, pose, rng, 0.01, 6.0);
      const auto begin = std::chrono::steady_clock::now();
      const auto result = relocalizer.process(scan, pose);
      frame_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count());
      if (result.state == omnislam::slam::LocalizationState::kLocalized) {
        ++localized, frames_needed += frame;
        if ((result.T_map_base.translation() - pose.translation()).norm() <= 0.05) ++correct;
        break;
      }
      pose = pose * omnislam::test::pose(0.1, 0.0, 0.05);
    }
  }
  std::printf(
      "| building %dx%d rooms (%.0f x %.0f m) | %zu | 10 | %d (%d / %d) | %.1f | %.1f / %.1f / %.1f |\n",
      side, side, side * 5.0, side * 5.0, map.size(), localized, correct, localized - correct,
      localized > 0 ? static_cast<double>(frames_needed) / localized : 0.0, quantile(frame_ms, 0.5),
      quantile(frame_ms, 0.99), quantile(frame_ms, 1.0));
}

// The starts not localized, as runs of consecutive frames ("153-179"): a run is a stretch of
// the path whose next max_frames frames never tell it from somewhere else on the map.
void print_missed(const std::vector<int> &missed) {
  if (missed.empty()) return;
  std::printf("  not localized, starting at frames:");
  for (std::size_t i = 0; i < missed.size();) {
    std::size_t j = i;
    while (j + 1 < missed.size() && missed[j + 1] == missed[j] + 1) ++j;
    if (j == i) {
      std::printf(" %d", missed[i]);
    } else {
      std::printf(" %d-%d", missed[i], missed[j]);
    }
    i = j + 1;
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char **argv) {
  // [--frames N] [DATASET_DIR...]: each start gets N frames (10) to localize.
  std::vector<std::string> datasets;
  int max_frames = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--frames" && i + 1 < argc) {
      max_frames = std::max(1, std::atoi(argv[++i]));
    } else {
      datasets.push_back(arg);
    }
  }
  const bool defaults = datasets.empty();
  if (defaults) {
    for (const char *name : {"sim-room-37", "sim-room-turning", "l-room-1lap", "office-real"})
      datasets.push_back(std::string(OMNISLAM_DEFAULT_DATASETS) + "/" + name);
  }
  std::printf(
      "| dataset | map points | starts | localized (correct / wrong) | frames to localize | ms per frame p50 "
      "/ p99 / max |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const std::string &dir : datasets) {
    const auto run = omnislam::test::build_localization_run(dir);
    const auto outcome = omnislam::test::relocalize_from_every_frame(run, max_frames);
    std::printf("| %s | %zu | %d | %d (%d / %d) | %.1f | %.1f / %.1f / %.1f |\n",
                dir.substr(dir.find_last_of('/') + 1).c_str(), run.map.size(), outcome.starts,
                outcome.localized, outcome.correct, outcome.wrong,
                outcome.localized > 0 ? static_cast<double>(outcome.frames_needed) / outcome.localized : 0.0,
                quantile(outcome.frame_ms, 0.5), quantile(outcome.frame_ms, 0.99),
                quantile(outcome.frame_ms, 1.0));
    print_missed(outcome.missed);
  }
  if (defaults) {
    for (const int side : {4, 8}) building_row(side);
  }
  return 0;
}
