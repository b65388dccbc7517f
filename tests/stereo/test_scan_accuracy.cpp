#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <vector>

#include "omnislam/degrade/degradation.hpp"
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

// The front-end's configuration for a dataset: its camera and camera height, the rest default.
omnislam::stereo::ScanConfig scan_config_of(const omnislam::test::TruthDataset &data) {
  omnislam::stereo::ScanConfig config;
  config.camera = data.info.camera;
  config.camera_height_m = data.info.camera_height_m;
  return config;
}

// `camera` replaces the dataset's camera and rig; `first` > 0 scans only the first frames;
// `degradation` replaces the default factors of a degraded run.
omnislam::test::ScanAccuracy scan_accuracy(const char *name, std::size_t frames, bool degraded,
                                           const std::optional<omnislam::mirror::MirrorConfig> &camera = {},
                                           std::size_t first = 0,
                                           const omnislam::degrade::DegradationConfig &degradation = {}) {
  const std::filesystem::path dir = dataset_dir(name);
  INFO("dataset " << dir << " (render it with scripts/render-dataset " << name << ")");
  REQUIRE(std::filesystem::is_regular_file(dir / "dataset.yaml"));
  const omnislam::test::TruthDataset data = omnislam::test::load_truth_dataset(dir);
  REQUIRE(data.images.size() == frames);

  omnislam::stereo::ScanConfig config = scan_config_of(data);
  if (camera) config.camera = *camera;
  omnislam::stereo::ScanReconstructor reconstructor(config);
  // Every factor of the degradation stage at its default, seed 1 (as replay --degrade all).
  const omnislam::degrade::Degrader degrader(degradation, data.images.front().size());
  omnislam::test::ScanAccuracy accuracy;
  for (std::size_t i = 0; i < (first > 0 ? first : data.images.size()); ++i) {
    cv::Mat image = data.images[i];
    if (degraded) {
      omnislam::degrade::Degraded result = degrader.apply(image, static_cast<int>(i) + 1);
      REQUIRE(result.error.empty());
      image = result.image;
    }
    const omnislam::stereo::LocalScan scan = reconstructor.reconstruct(image);
    REQUIRE(scan.status == omnislam::stereo::ScanStatus::kOk);
    REQUIRE(scan.free_range_m.size() == 360u);
    accuracy.add(scan, data.poses[i], data.segments);
  }
  std::printf("%s%s%s scan accuracy: %s\n", name, degraded ? " (degraded)" : "",
              camera ? " (camera replaced)" : "", accuracy.summary().c_str());
  return accuracy;
}

}  // namespace

TEST_CASE("sim-room-37: local scans against the floor plan", "[stereo][accuracy][dataset]") {
  const omnislam::test::ScanAccuracy accuracy = scan_accuracy("sim-room-37", 37, false);
  CHECK(accuracy.points > 37 * 150);
  CHECK(accuracy.median_relative_error() <= 0.02);
  CHECK(accuracy.near_segment_share() >= 0.90);
  CHECK(accuracy.coverage() >= 0.80);
  // Free floor is known in most columns; where it reaches past the plan, it is mostly the
  // floor seen under an overhang (the table top, the sphere), which the plan draws as solid.
  // A column whose boundary is an edge above the floor with no floor contact says nothing of
  // the floor in front of it on this plain floor (87.7%, 5.0% past the plan; 96.1% and 8.5%
  // when such a column claimed the floor free up to the edge, across the platform's top).
  CHECK(accuracy.free_known_share() >= 0.85);
  CHECK(accuracy.free_overclaim_share() <= 0.08);
}

// Tiled floor, soft shadows, sunlight; then every sensor factor on top. Measured: noise-free
// 0.18% / 97.4% within 0.1 m / coverage 89.7%; degraded 0.23% / 96.7% / 83.6% (the issue:
// median <= 2%, >= 90% within 0.1 m).
TEST_CASE("sim-room-37-real: local scans against the floor plan", "[stereo][accuracy][dataset]") {
  const omnislam::test::ScanAccuracy clean = scan_accuracy("sim-room-37-real", 37, false);
  CHECK(clean.median_relative_error() <= 0.02);
  CHECK(clean.near_segment_share() >= 0.90);
  CHECK(clean.coverage() >= 0.80);
  CHECK(clean.free_known_share() >= 0.90);
  CHECK(clean.free_overclaim_share() <= 0.15);
  const omnislam::test::ScanAccuracy degraded = scan_accuracy("sim-room-37-real", 37, true);
  CHECK(degraded.median_relative_error() <= 0.02);
  CHECK(degraded.near_segment_share() >= 0.90);
  CHECK(degraded.coverage() >= 0.80);
  CHECK(degraded.free_known_share() >= 0.90);
  CHECK(degraded.free_overclaim_share() <= 0.15);
}

// The office: hexagon carpet, a pillar, furniture, camera 0.8 m up, robot facing its travel.
// Measured: noise-free 0.27% / 93.4% within 0.1 m / coverage 87.0%; degraded 0.31% / 91.5%
// / 80.8% (86.1% / 82.1% before rows unexplained by both hypotheses stopped voting and twins
// within the frame's placement error stopped making low obstacles by themselves; 91.2% /
// 90.5% before the twins of floor edges beyond an undecided edge counted; coverage counts
// degrees with any point, so dropping wrong points lowers it). What remains: floor texture
// at 3-5 m where too few rows and twins lie between it and the wall for the test to decide,
// carpet edges whose twin is more than the placement error off, and missed table tops.
TEST_CASE("office-real: local scans against the floor plan", "[stereo][accuracy][dataset]") {
  const omnislam::test::ScanAccuracy clean = scan_accuracy("office-real", 45, false);
  CHECK(clean.median_relative_error() <= 0.02);
  CHECK(clean.near_segment_share() >= 0.90);
  CHECK(clean.coverage() >= 0.85);
  const omnislam::test::ScanAccuracy degraded = scan_accuracy("office-real", 45, true);
  CHECK(degraded.median_relative_error() <= 0.02);
  CHECK(degraded.near_segment_share() >= 0.90);
  CHECK(degraded.coverage() >= 0.79);
  CHECK(degraded.free_known_share() >= 0.90);
  CHECK(degraded.free_overclaim_share() <= 0.15);
}

// The L-room with oak planks, a rug, pendant lamps over the tables and sunlight. Measured:
// degraded 0.64% / 94.1% within 0.1 m / coverage 81.1% (93.3% / 81.6% before the changes
// noted at the office); free range known in 86.3% of columns (94.3% when an edge above the
// floor with no floor contact claimed the floor free up to it).
TEST_CASE("l-room-1lap-real: local scans against the floor plan", "[stereo][accuracy][dataset]") {
  const omnislam::test::ScanAccuracy degraded = scan_accuracy("l-room-1lap-real", 60, true);
  CHECK(degraded.median_relative_error() <= 0.02);
  CHECK(degraded.near_segment_share() >= 0.90);
  CHECK(degraded.coverage() >= 0.80);
  CHECK(degraded.free_known_share() >= 0.82);
  CHECK(degraded.free_overclaim_share() <= 0.17);
}

// Dim light: the camera's gain ten times up (a full well of 600 electrons at grey 255 and 20
// grey levels of read noise: 21 grey levels of noise at mid-grey, against 3 by default), every
// other factor as usual. Canny's thresholds rise with the noise each frame measures (no row
// below what the noise alone reaches at one pixel of a panorama). Measured over every frame:
// 88.1% of the points within 0.1 m, median relative error 1.98%, 141 points a frame (every
// third frame with scripts/eval-scans: floor contacts 88.7% within 0.1 m and 0.69% median
// error, against 36.5% and 27.2% when the thresholds ignored the noise, whose edges crowded
// the columns nearest the robot).
TEST_CASE("sim-room-37-real in dim light: the noise's own edges are not taken for walls",
          "[stereo][accuracy][dataset][noise]") {
  omnislam::degrade::DegradationConfig dim;
  dim.noise.full_well_e = 600.0;
  dim.noise.read_noise_dn = 20.0;
  const omnislam::test::ScanAccuracy accuracy = scan_accuracy("sim-room-37-real", 37, true, {}, 0, dim);
  CHECK(accuracy.median_relative_error() <= 0.03);
  CHECK(accuracy.near_segment_share() >= 0.85);
  CHECK(accuracy.points > 37 * 100);
}

// Issue 12: the first 4 frames of sim-room-37 rendered through a rig assembled with known
// errors (scripts/render-dataset sim-room-37 --out datasets/sim-room-37-rig --frames 4
// --rig-center-px 514.0 509.5 --rig-focal-scale 1.008 --rig-mirror-dz-mm 2.5
// --rig-tilt-deg 0.8 -0.5 --rig-offset-mm 0.7 -0.4), scanned with the rig its dataset.yaml
// declares, with the designed mirror and lens at the true centre, and as designed.
TEST_CASE("sim-room-37-rig: a misaligned rig scans as well as the designed one with its true parameters",
          "[stereo][accuracy][dataset][rig]") {
  const omnislam::test::ScanAccuracy designed = scan_accuracy("sim-room-37", 37, false, {}, 4);
  const omnislam::test::ScanAccuracy true_rig = scan_accuracy("sim-room-37-rig", 4, false);
  const omnislam::test::TruthDataset data =
      omnislam::test::load_truth_dataset(dataset_dir("sim-room-37-rig"));
  REQUIRE_FALSE(data.info.camera.rig.nominal());
  omnislam::mirror::MirrorConfig centre_only = data.info.camera;
  centre_only.rig = {};
  const omnislam::test::ScanAccuracy centre_known = scan_accuracy("sim-room-37-rig", 4, false, centre_only);
  omnislam::mirror::MirrorConfig as_designed;
  const omnislam::test::ScanAccuracy nominal = scan_accuracy("sim-room-37-rig", 4, false, as_designed);
  // Measured when written (4 frames): designed rig 0.096% median (p90 1.22%), 99.3% within
  // 0.1 m, coverage 84.1%, 1219 points; the misaligned rig with its parameters 0.100% (p90
  // 3.15%), 99.3%, 78.7%, 1139 points (the outer lobe's rows the inner lobe's rim hides at
  // some azimuths are lost); with the designed mirror and lens, true centre or not: 55%
  // median, 6% within 0.1 m.
  CHECK(true_rig.median_relative_error() <= 1.15 * designed.median_relative_error());
  CHECK(true_rig.near_segment_share() >= designed.near_segment_share() - 0.01);
  CHECK(true_rig.points >= 0.9 * designed.points);
  CHECK(true_rig.coverage() >= 0.75);
  for (const omnislam::test::ScanAccuracy *wrong : {&centre_known, &nominal}) {
    CHECK(wrong->median_relative_error() >= 20.0 * designed.median_relative_error());
    CHECK(wrong->near_segment_share() <= 0.5);
  }
}

// The frame's placement error (the spread of floor edges' outer twins about where the floor
// puts them) grows when blur and noise are added: the degradation stage's defocus and sensor
// noise move each edge by a fraction of a row.
TEST_CASE("sim-room-37-real: the twin spread measures the placement error the degradation adds",
          "[stereo][floor][dataset]") {
  const omnislam::test::TruthDataset data =
      omnislam::test::load_truth_dataset(dataset_dir("sim-room-37-real"));
  omnislam::stereo::ScanReconstructor reconstructor(scan_config_of(data));
  const omnislam::degrade::Degrader degrader({}, data.images.front().size());
  double clean = 0.0, degraded = 0.0;
  constexpr int kFrames = 6;
  for (int i = 0; i < kFrames; ++i) {
    const cv::Mat &image = data.images[static_cast<std::size_t>(i) * 6];
    clean += reconstructor.reconstruct(image).stats.twin_spread_px;
    const omnislam::degrade::Degraded result = degrader.apply(image, i * 6 + 1);
    REQUIRE(result.error.empty());
    degraded += reconstructor.reconstruct(result.image).stats.twin_spread_px;
  }
  clean /= kFrames;
  degraded /= kFrames;
  std::printf("sim-room-37-real twin spread: clean %.3f px, degraded %.3f px\n", clean, degraded);
  CHECK(clean > 0.0);
  CHECK(clean < 1.0);
  CHECK(degraded > clean);
}

// office-real frame 37 looks along carpet to a wall ~4.9 m away (azimuths 164-179 deg). At
// that range the rows between a carpet edge and the wall are too few for the floor-or-wall
// test to decide, so each carpet edge is undecided; the twins of the carpet's edges farther
// out sit at the floor's rows, ~1-2 px from where a surface standing at the nearer edge
// would put them, so the floor is seen past it. Measured when written (noise-free), median
// relative range error of the 15 columns: -5.2% (-15% before the twins counted: carpet edges
// ~4.2 m away were taken for the wall); the rest are carpet edges one hexagon short. On the
// degraded frame (placement error 0.385 px against 0.128) the evidence mostly stays short of
// the 1% error rate and the median stays at -16%.
TEST_CASE("office-real: carpet edges short of a far wall are floor when the twins beyond say so",
          "[stereo][floor][dataset]") {
  const omnislam::test::TruthDataset data = omnislam::test::load_truth_dataset(dataset_dir("office-real"));
  REQUIRE(data.images.size() == 45u);
  omnislam::stereo::ScanReconstructor reconstructor(scan_config_of(data));
  constexpr std::size_t kFrame = 37;
  const omnislam::test::Pose2 &pose = data.poses[kFrame - 1];
  const omnislam::stereo::LocalScan scan = reconstructor.reconstruct(data.images[kFrame - 1]);
  std::vector<double> errors;
  for (const omnislam::stereo::ScanPoint &point : scan.points) {
    const double azimuth_deg = point.azimuth_rad * 180.0 / M_PI;
    if (azimuth_deg < 164.0 || azimuth_deg > 179.0) continue;
    const auto truth_m =
        omnislam::test::ray_cast_m(data.segments, pose.x_m, pose.y_m, pose.yaw_rad + point.azimuth_rad);
    REQUIRE(truth_m);
    errors.push_back(point.range_m / *truth_m - 1.0);
  }
  REQUIRE(errors.size() >= 12u);
  const auto middle = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
  std::nth_element(errors.begin(), middle, errors.end());
  std::printf(
      "office-real frame 37, far carpet: %zu columns, median relative range error %.1f%%, twin spread %.3f "
      "px\n",
      errors.size(), 100.0 * *middle, static_cast<double>(scan.stats.twin_spread_px));
  CHECK(*middle >= -0.10);
}

// Each point says how far its range moves per pixel of image error. A floor contact is
// ranged from one row and the camera height, a table edge by stereo across the 150 mm
// between the lobes' foci: at the same range the stereo point's moves several times
// further, and a contact's grows with its range (about as its square).
TEST_CASE("l-room-1lap-real: range per pixel of floor contacts and of stereo points",
          "[stereo][floor][dataset]") {
  const omnislam::test::TruthDataset data =
      omnislam::test::load_truth_dataset(dataset_dir("l-room-1lap-real"));
  omnislam::stereo::ScanReconstructor reconstructor(scan_config_of(data));
  std::vector<double> near_contacts, far_contacts, mid_contacts, mid_stereo;
  for (std::size_t i = 0; i < data.images.size(); i += 6) {
    for (const omnislam::stereo::ScanPoint &point : reconstructor.reconstruct(data.images[i]).points) {
      const double per_px = point.range_per_px_m;
      REQUIRE(per_px > 0.0);
      const bool contact = std::abs(point.z_m) < 1e-6;
      if (contact) REQUIRE(std::isfinite(per_px));
      if (contact && point.range_m < 1.5) near_contacts.push_back(per_px);
      if (contact && point.range_m > 3.0) far_contacts.push_back(per_px);
      if (point.range_m > 2.0 && point.range_m < 3.0) (contact ? mid_contacts : mid_stereo).push_back(per_px);
    }
  }
  auto median = [](std::vector<double> values) {
    REQUIRE(values.size() >= 10u);
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  };
  const double near = median(near_contacts), far = median(far_contacts);
  const double contact_2_3 = median(mid_contacts), stereo_2_3 = median(mid_stereo);
  std::printf(
      "l-room-1lap-real range per px: contacts < 1.5 m %.4f, > 3 m %.4f, 2-3 m %.4f; stereo 2-3 m %.4f\n",
      near, far, contact_2_3, stereo_2_3);
  CHECK(far > 4.0 * near);
  CHECK(stereo_2_3 > 4.0 * contact_2_3);
}

TEST_CASE("l-room-1lap-real: edges above the floor are marked elevated, floor contacts never, however ranged",
          "[stereo][floor][dataset]") {
  // The occupancy grid keeps what was seen above the floor against floor seen under it
  // (grid/occupancy_grid.hpp), so the flag must follow the search's decision, not the range's
  // source: with floor contacts ranged by stereo they are still on the floor.
  const omnislam::test::TruthDataset data =
      omnislam::test::load_truth_dataset(dataset_dir("l-room-1lap-real"));
  for (const bool floor_plane : {true, false}) {
    omnislam::stereo::ScanConfig config = scan_config_of(data);
    config.stereo.floor.floor_plane_range = floor_plane;
    omnislam::stereo::ScanReconstructor reconstructor(config);
    int elevated = 0, above = 0, tables = 0, contacts = 0;
    for (std::size_t i = 0; i < data.images.size(); i += 10) {
      for (const omnislam::stereo::ScanPoint &point : reconstructor.reconstruct(data.images[i]).points) {
        if (point.floor_ranged) CHECK_FALSE(point.elevated);
        if (point.elevated) {
          ++elevated;
          above += point.z_m > 0.04 ? 1 : 0;                     // the skirting's top is 0.08 m up
          tables += point.z_m > 0.6 && point.z_m < 0.9 ? 1 : 0;  // the tables' tops 0.75 m
        } else {
          ++contacts;
          CHECK(std::abs(point.z_m) < 0.1);
        }
      }
    }
    INFO("floor-plane range " << floor_plane << ": " << elevated << " elevated (" << above << " above 4 cm, "
                              << tables << " at the tables' height), " << contacts << " on the floor");
    CHECK(elevated > 300);
    CHECK(above >= 0.99 * elevated);
    CHECK(tables > 300);
    CHECK(contacts > 300);
  }
}
