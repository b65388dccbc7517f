// bench_relocalize [DATASET...]: global relocalisation on the saved map of each dataset (the
// map its replay builds), started at every frame with no pose: success, frames needed, and
// the time of each relocaliser frame (a search of the whole map, the refinement of every
// hypothesis) on one thread. Default: the bundled rooms.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "relocalization_run.hpp"

namespace {

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1))];
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<std::string> datasets(argv + 1, argv + argc);
  if (datasets.empty()) {
    for (const char *name : {"sim-room-37", "sim-room-turning", "l-room-1lap", "office-real"})
      datasets.push_back(std::string(OMNISLAM_DEFAULT_DATASETS) + "/" + name);
  }
  std::printf("| dataset | map points | starts | localized (correct / wrong) | frames to localize | ms per frame p50 / p99 / max |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const std::string &dir : datasets) {
    const auto run = omnislam::test::build_localization_run(dir);
    const auto outcome = omnislam::test::relocalize_from_every_frame(run, 10);
    std::printf("| %s | %zu | %d | %d (%d / %d) | %.1f | %.1f / %.1f / %.1f |\n",
                dir.substr(dir.find_last_of('/') + 1).c_str(), run.map.size(), outcome.starts, outcome.localized,
                outcome.correct, outcome.wrong,
                outcome.localized > 0 ? static_cast<double>(outcome.frames_needed) / outcome.localized : 0.0,
                quantile(outcome.frame_ms, 0.5), quantile(outcome.frame_ms, 0.99), quantile(outcome.frame_ms, 1.0));
  }
  return 0;
}
