#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "omnislam/stereo/scan_reconstructor.hpp"
#include "scan_truth.hpp"

// Acceptance of the stereo issue on a rendered dataset (architecture.md format). The
// dataset directory comes from $OMNISLAM_DATASETS (default: the source tree's datasets/);
// a missing dataset fails the test.

namespace {

std::filesystem::path dataset_dir(const char *name) {
  const char *root = std::getenv("OMNISLAM_DATASETS");
  return std::filesystem::path(root != nullptr ? root : OMNISLAM_DEFAULT_DATASETS) / name;
}

}  // namespace

TEST_CASE("sim-room-37: local scans against the floor plan", "[stereo][accuracy][dataset]") {
  const std::filesystem::path dir = dataset_dir("sim-room-37");
  INFO("dataset " << dir << " (render it with scripts/render-dataset sim-room-37)");
  REQUIRE(std::filesystem::is_regular_file(dir / "dataset.yaml"));
  const omnislam::test::TruthDataset data = omnislam::test::load_truth_dataset(dir);
  REQUIRE(data.images.size() == 37u);

  omnislam::stereo::ScanConfig config;
  config.camera = data.info.camera;
  config.camera_height_m = data.info.camera_height_m;
  omnislam::stereo::ScanReconstructor reconstructor(config);
  omnislam::test::ScanAccuracy accuracy;
  for (std::size_t i = 0; i < data.images.size(); ++i) {
    const omnislam::stereo::LocalScan scan = reconstructor.reconstruct(data.images[i]);
    REQUIRE(scan.status == omnislam::stereo::ScanStatus::kOk);
    accuracy.add(scan, data.poses[i], data.segments);
  }
  std::printf("sim-room-37 scan accuracy: %s\n", accuracy.summary().c_str());
  CHECK(accuracy.points > 37 * 150);
  CHECK(accuracy.median_relative_error() <= 0.02);
  CHECK(accuracy.near_segment_share() >= 0.90);
  CHECK(accuracy.coverage() >= 0.80);
}
