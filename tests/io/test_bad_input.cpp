#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "omnislam/io/config.hpp"
#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/run_files.hpp"

// Bad input to the text readers: each error names file:line and what is wrong.
namespace fs = std::filesystem;

namespace {

fs::path write_file(const std::string &name, const std::string &text) {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-bad-input";
  fs::create_directories(dir);
  const fs::path file = dir / name;
  std::ofstream(file) << text;
  return file;
}

}  // namespace

TEST_CASE("TUM odometry: NaN, infinity, time going backwards and malformed lines name file:line",
          "[io][bad-input]") {
  using omnislam::io::read_tum_file;
  const auto nan = write_file("nan.tum", "# t x y z qx qy qz qw\n0 0 0 0 0 0 0 1\n0.1 nan 0 0 0 0 0 1\n");
  CHECK_THROWS_WITH(read_tum_file(nan), Catch::EndsWith("nan.tum:3: 'x' is 'nan', not a finite number"));
  const auto inf = write_file("inf.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 -inf 1\n");
  CHECK_THROWS_WITH(read_tum_file(inf), Catch::EndsWith("inf.tum:2: 'qz' is '-inf', not a finite number"));
  const auto huge = write_file("huge.tum", "1e999 0 0 0 0 0 0 1\n");
  CHECK_THROWS_WITH(read_tum_file(huge),
                    Catch::EndsWith("huge.tum:1: 't' is '1e999', out of the range of a double"));
  const auto backwards =
      write_file("backwards.tum", "0.0 0 0 0 0 0 0 1\n0.2 0 0 0 0 0 0 1\n\n0.1 0 0 0 0 0 0 1\n");
  CHECK_THROWS_WITH(read_tum_file(backwards),
                    Catch::EndsWith("backwards.tum:4: time goes backwards: t = 0.1 s after t = 0.200000 s"));
  const auto text = write_file("text.tum", "0 1 2 3 4 5 6 seven\n");
  CHECK_THROWS_WITH(read_tum_file(text), Catch::EndsWith("text.tum:1: 'qw' is 'seven', not a number"));
  const auto extra = write_file("extra.tum", "0 0 0 0 0 0 0 1 9\n");
  CHECK_THROWS_WITH(
      read_tum_file(extra),
      Catch::EndsWith("extra.tum:1: expected 8 numbers \"t x y z qx qy qz qw\", found 9 fields"));
  const auto zero = write_file("zero.tum", "0 0 0 0 0 0 0 0\n");
  CHECK_THROWS_WITH(read_tum_file(zero), Catch::EndsWith("zero.tum:1: the quaternion (qx qy qz qw) is zero"));
  // Equal stamps, a leading '+' and CRLF line ends are fine.
  const auto ok = write_file("ok.tum", "0 0 0 0 0 0 0 1\r\n0 +1.5 0 0 0 0 0 1\r\n");
  const auto poses = read_tum_file(ok);
  REQUIRE(poses.size() == 2);
  CHECK(poses[1].x_m == 1.5);
}

TEST_CASE("thesis odometry: non-finite and missing values are named", "[io][bad-input]") {
  using omnislam::io::read_thesis_odometry;
  const auto nan = write_file("nan.txt", "2\n0.0 0.0\nnan 0\n");
  CHECK_THROWS_WITH(read_thesis_odometry(nan),
                    Catch::EndsWith("nan.txt:3: 'distance_mm' is 'nan', not a finite number"));
  const auto missing = write_file("missing.txt", "2\n0.0 0.0\n250.0\n");
  CHECK_THROWS_WITH(read_thesis_odometry(missing),
                    Catch::EndsWith("missing.txt:3: expected \"distance_mm angle_deg\", found 1 fields"));
  const auto count = write_file("count.txt", "two\n0.0 0.0\n");
  CHECK_THROWS_WITH(read_thesis_odometry(count), Catch::EndsWith("count.txt:1: expected the frame count"));
}

TEST_CASE("floor plan and map CSV: empty fields, NaN and bad counts are named", "[io][bad-input]") {
  const auto empty = write_file("floor-empty.csv", "x1,y1,x2,y2\n0,0,1,0\n0,,1,1\n");
  CHECK_THROWS_WITH(omnislam::io::read_floorplan_csv(empty),
                    Catch::EndsWith("floor-empty.csv:3: 'y1' is '', not a number"));
  const auto nan = write_file("floor-nan.csv", "x1,y1,x2,y2\n0,0,1,NaN\n");
  CHECK_THROWS_WITH(omnislam::io::read_floorplan_csv(nan),
                    Catch::EndsWith("floor-nan.csv:2: 'y2' is 'NaN', not a finite number"));
  const auto hits = write_file("map-hits.csv", "x,y,hits\n0.5,0.25,3\n0.5,0.25,2.5\n");
  CHECK_THROWS_WITH(omnislam::io::read_map_csv(hits),
                    Catch::EndsWith("map-hits.csv:3: 'hits' is '2.5', not an integer"));
  const auto zero = write_file("map-zero.csv", "x,y,hits\n0.5,0.25,0\n");
  CHECK_THROWS_WITH(omnislam::io::read_map_csv(zero),
                    Catch::EndsWith("map-zero.csv:2: 'hits' must be in 1..1e9"));
  const auto ok = write_file("map-ok.csv", "x,y,hits\n0.5, -0.25 ,3\n");
  const auto points = omnislam::io::read_map_csv(ok);
  REQUIRE(points.size() == 1);
  CHECK(points[0].y_m == -0.25);
  CHECK(points[0].hits == 3);
}

TEST_CASE(
    "config: wrong type, out of range, non-finite and unknown keys are ConfigErrors naming key and line",
    "[io][config][bad-input]") {
  using omnislam::io::ConfigError;
  using omnislam::io::load_config;
  CHECK_THROWS_AS(
      load_config(write_file("unknown.yaml", "slam:\n  overlap: 0.5\n  localisation_only: true\n")),
      ConfigError);
  CHECK_THROWS_WITH(
      load_config(write_file("unknown.yaml", "slam:\n  overlap: 0.5\n  localisation_only: true\n")),
      Catch::EndsWith("unknown.yaml:3:3: unknown key 'slam.localisation_only'"));
  CHECK_THROWS_WITH(load_config(write_file("range.yaml", "slam:\n  fusion_radius_m: -0.1\n")),
                    Catch::EndsWith("range.yaml:2:20: 'slam.fusion_radius_m' must be positive"));
  CHECK_THROWS_WITH(load_config(write_file("prune.yaml", "slam:\n\n  prune_every: -5\n")),
                    Catch::EndsWith("prune.yaml:3:16: 'slam.prune_every' must be >= 0"));
  CHECK_THROWS_WITH(load_config(write_file("nan.yaml", "stereo:\n  occlusion_cost: .nan\n")),
                    Catch::EndsWith("nan.yaml:2:19: 'stereo.occlusion_cost' must be a finite number"));
  CHECK_THROWS_WITH(load_config(write_file("iterations.yaml", "slam: {max_iterations: 100000}\n")),
                    Catch::EndsWith("iterations.yaml:1:24: 'slam.max_iterations' must be in 1..1000"));
  CHECK_THROWS_WITH(load_config(write_file("list.yaml", "- camera\n- slam\n")),
                    Catch::EndsWith("list.yaml:1:1: the file must be a mapping of keys"));
  CHECK_THROWS_WITH(load_config(write_file("key.yaml", "slam:\n  [a, b]: 1\n")),
                    Catch::EndsWith("key.yaml:2:3: a key of 'slam' is not a plain name"));
  CHECK_THROWS_WITH(
      load_config(write_file("policy.yaml", "persistence:\n  on_corrupt_snapshot: ignore\n")),
      Catch::EndsWith("policy.yaml:2:24: 'persistence.on_corrupt_snapshot' must be start_fresh or refuse"));
  CHECK_THROWS_WITH(load_config(write_file("start.yaml", "persistence: {start_pose: guess}\n")),
                    Catch::EndsWith("'persistence.start_pose' must be auto, saved or search"));
  CHECK_THROWS_AS(load_config("/nonexistent/omnislam.yaml"), ConfigError);
}

TEST_CASE("config: persistence and localization keys", "[io][config]") {
  const auto file = write_file("persistence.yaml",
                               "slam: {localization_only: true}\n"
                               "persistence:\n"
                               "  state_dir: /var/lib/omnislam-test\n"
                               "  resume: false\n"
                               "  snapshot_period_s: 5\n"
                               "  on_corrupt_snapshot: refuse\n"
                               "  start_pose: search\n"
                               "service: {stage_timeout_s: 2.5}\n");
  const omnislam::io::Config config = omnislam::io::load_config(file);
  CHECK(config.slam.localization_only);
  CHECK(config.persistence.state_dir == "/var/lib/omnislam-test");
  CHECK_FALSE(config.persistence.resume);
  CHECK(config.service.stage_timeout_s == 2.5);
  CHECK(config.persistence.snapshot_period_s == 5.0);
  CHECK(config.persistence.refuse_corrupt_snapshot);
  CHECK(config.persistence.start_pose == omnislam::io::PersistenceConfig::StartPose::kSearch);
  const omnislam::io::Config defaults;
  CHECK(defaults.persistence.start_pose == omnislam::io::PersistenceConfig::StartPose::kAuto);
  CHECK_FALSE(defaults.slam.localization_only);
  CHECK(defaults.persistence.snapshot_period_s == 30.0);
  CHECK_FALSE(defaults.persistence.refuse_corrupt_snapshot);
  CHECK(defaults.persistence.resume);
  CHECK(defaults.persistence.state_dir.empty());
  CHECK(defaults.service.stage_timeout_s == 5.0);
  CHECK(defaults.service.input.odometry_max_gap_s == 0.5);
  CHECK(defaults.service.input.odometry_max_extrapolation_s == 0.2);
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("gap.yaml",
                                                         "input: {source: camera, odometry: dds, "
                                                         "odometry_max_gap_s: 0}\n")),
                    Catch::Contains("'input.odometry_max_gap_s' must be positive"));
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("stage.yaml", "service:\n  stage_timeout_s: 0\n")),
                    Catch::EndsWith("stage.yaml:2:20: 'service.stage_timeout_s' must be positive"));
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("resume.yaml", "persistence: {resume: maybe}\n")),
                    Catch::Contains("resume.yaml:1:23: 'persistence.resume'"));
}

TEST_CASE("dataset.yaml: an images pattern other than one %d field is refused", "[io][bad-input]") {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-bad-input" / "pattern";
  fs::create_directories(dir);
  for (const char *pattern :
       {"images/%s.png", "images/%06d-%06d.png", "images/frame.png", "images/%n%d.png", "images/%123d.png"}) {
    std::ofstream(dir / "dataset.yaml") << "frames: 2\nimages: \"" << pattern << "\"\n";
    CHECK_THROWS_WITH(
        omnislam::io::read_dataset_info(dir),
        Catch::Contains("dataset.yaml:2:") && Catch::Contains("'images' must be a path with one"));
  }
  std::ofstream(dir / "dataset.yaml") << "frames: 2\nimages: \"img-100%%/%04d.png\"\n";
  CHECK(omnislam::io::read_dataset_info(dir).image(7) == dir / "img-100%/0007.png");
}

TEST_CASE("dataset.yaml: the camera height a calibration wrote into the camera line", "[io][bad-input]") {
  // `omnislam calibrate target` writes camera: {..., camera_height_m}: the height its floor
  // boards measured, which goes with the rig it fitted.
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-bad-input" / "height";
  fs::create_directories(dir);
  std::ofstream(dir / "dataset.yaml") << "camera: {focal_scale: 1.002, camera_height_m: 0.9983}\nframes: 2\n";
  CHECK(omnislam::io::read_dataset_info(dir).camera_height_m == 0.9983);
  std::ofstream(dir / "dataset.yaml") << "camera: {camera_height_m: 0.9983}\ncamera_height_m: 0.9983\n";
  CHECK(omnislam::io::read_dataset_info(dir).camera_height_m == 0.9983);
  std::ofstream(dir / "dataset.yaml") << "camera_height_m: 0.8\n";
  CHECK(omnislam::io::read_dataset_info(dir).camera_height_m == 0.8);
  std::ofstream(dir / "dataset.yaml") << "camera: {camera_height_m: 0.9983}\ncamera_height_m: 1.0\n";
  CHECK_THROWS_WITH(
      omnislam::io::read_dataset_info(dir),
      Catch::Contains("dataset.yaml:2:") && Catch::Contains("'camera_height_m' disagrees with "
                                                            "camera.camera_height_m (0.998300)"));
  std::ofstream(dir / "dataset.yaml") << "camera: {camera_height_m: -1}\n";
  CHECK_THROWS_WITH(omnislam::io::read_dataset_info(dir),
                    Catch::Contains("'camera.camera_height_m' must be positive"));
}
