#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"

namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string &name) {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-files" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST_CASE("camera images: grey or colour in, grey out; bad files name the file", "[io][image]") {
  const fs::path dir = scratch("images");
  const omnislam::mirror::MirrorConfig camera;
  cv::Mat colour(1024, 1024, CV_8UC3, cv::Scalar(10, 200, 30));
  cv::imwrite((dir / "colour.png").string(), colour);
  const cv::Mat grey = omnislam::io::read_camera_image(dir / "colour.png", camera);
  CHECK(grey.type() == CV_8UC1);
  CHECK(grey.rows == 1024);
  cv::imwrite((dir / "small.png").string(), cv::Mat(100, 120, CV_8UC1, cv::Scalar(0)));
  CHECK_THROWS_WITH(
      omnislam::io::read_camera_image(dir / "small.png", camera),
      Catch::Contains("small.png") && Catch::Contains("120x100") && Catch::Contains("1024x1024"));
  std::ofstream(dir / "empty.png").flush();
  CHECK_THROWS_WITH(omnislam::io::read_camera_image(dir / "empty.png", camera),
                    Catch::Contains("empty.png") && Catch::Contains("empty"));
  std::ofstream(dir / "text.png") << "not an image at all";
  CHECK_THROWS_WITH(omnislam::io::read_camera_image(dir / "text.png", camera),
                    Catch::Contains("text.png") && Catch::Contains("not a readable image"));
  CHECK_THROWS_WITH(omnislam::io::read_camera_image(dir / "missing.png", camera),
                    Catch::Contains("missing.png") && Catch::Contains("no such"));
}

TEST_CASE("dataset.yaml, groundtruth.tum and floorplan.csv", "[io][dataset]") {
  const fs::path dir = scratch("dataset");
  std::ofstream(dir / "dataset.yaml")
      << "name: tiny\n"
         "camera: {width: 1024, height: 1024, center_px: [511.5, 511.5], focal_mm: 25.0, "
         "pixel_pitch_mm: 0.00702051}\n"
         "mirror: thesis-2008\ncamera_height_m: 0.9\nframes: 2\nrate_hz: 5\n"
         "images: images/%06d.png\ngroundtruth: groundtruth.tum\nfloorplan: floorplan.csv\n"
         "odometry_noise: {model: thesis, seed: 1}\n";
  const omnislam::io::DatasetInfo info = omnislam::io::read_dataset_info(dir);
  CHECK(info.name == "tiny");
  CHECK(info.frames == 2);
  CHECK(info.camera_height_m == 0.9);
  CHECK(info.camera.pixel_pitch_mm == 0.00702051);
  CHECK(info.image(2) == dir / "images/000002.png");
  CHECK(info.floorplan == dir / "floorplan.csv");

  std::ofstream(dir / "groundtruth.tum")
      << "# t x y z qx qy qz qw\n0 1 2 0 0 0 0 1\n\n"
      << "0.2 1.5 2 0 0 0 " << std::sin(0.25) << " " << std::cos(0.25) << "\n";
  const auto poses = omnislam::io::read_tum_file(dir / "groundtruth.tum");
  REQUIRE(poses.size() == 2);
  CHECK(poses[1].x_m == 1.5);
  CHECK(poses[1].yaw_rad() == Approx(0.5));
  std::ofstream(dir / "floorplan.csv") << "x1,y1,x2,y2\n0,0,4,0\n4,0,4,8\n";
  const auto segments = omnislam::io::read_floorplan_csv(dir / "floorplan.csv");
  REQUIRE(segments.size() == 2);
  CHECK(segments[1].y2_m == 8.0);

  std::ofstream(dir / "bad.tum") << "0 1 2 3\n";
  CHECK_THROWS_WITH(omnislam::io::read_tum_file(dir / "bad.tum"), Catch::Contains("bad.tum:1"));
  std::ofstream(dir / "dataset.yaml") << "frames: many\n";
  CHECK_THROWS_WITH(omnislam::io::read_dataset_info(dir),
                    Catch::Contains("dataset.yaml:1:") && Catch::Contains("'frames'"));
}

TEST_CASE("thesis odometry.txt: cumulative translations, errors name file:line", "[io][odometry]") {
  const fs::path dir = scratch("thesis-odometry");
  { std::ofstream(dir / "odometry.txt") << "3\n0.0 0.0\n250.0 90.0\n500 180\n"; }
  const auto poses = omnislam::io::read_thesis_odometry(dir / "odometry.txt");
  REQUIRE(poses.size() == 3);
  CHECK(poses[1].x_m == Approx(0.0).margin(1e-12));
  CHECK(poses[1].y_m == Approx(0.25));
  CHECK(poses[2].x_m == Approx(-0.5));
  CHECK(poses[2].y_m == Approx(0.25));
  { std::ofstream(dir / "bad.txt") << "2\n0.0 0.0\n250.0 north\n"; }
  CHECK_THROWS_WITH(omnislam::io::read_thesis_odometry(dir / "bad.txt"), Catch::Contains("bad.txt:3"));
  { std::ofstream(dir / "count.txt") << "5\n0.0 0.0\n"; }
  CHECK_THROWS_WITH(omnislam::io::read_thesis_odometry(dir / "count.txt"), Catch::Contains("announces 5"));
  { std::ofstream(dir / "nan.txt") << "2\n0.0 0.0\nnan 0\n"; }
  CHECK_THROWS_WITH(omnislam::io::read_thesis_odometry(dir / "nan.txt"), Catch::Contains("nan.txt:3"));
}

TEST_CASE("thesis odometry.txt of a rendered dataset matches its odometry.tum", "[io][odometry]") {
  const fs::path dataset = fs::path(OMNISLAM_SOURCE_DIR) / "datasets" / "sim-room-37";
  const auto thesis = omnislam::io::read_thesis_odometry(dataset / "odometry.txt");
  const auto tum = omnislam::io::read_tum_file(dataset / "odometry.tum");
  REQUIRE(thesis.size() == tum.size());
  for (std::size_t i = 0; i < tum.size(); ++i) {
    CHECK(thesis[i].x_m == Approx(tum[i].x_m - tum[0].x_m).margin(1e-5));
    CHECK(thesis[i].y_m == Approx(tum[i].y_m - tum[0].y_m).margin(1e-5));
  }
}

TEST_CASE("looped dataset: the odometry continues across passes through the true step back to the start",
          "[io][dataset]") {
  // Truth: a square tour that ends 0.3 m short of its start; odometry: the truth with a
  // drift that grows along it, in a frame of its own.
  std::vector<Eigen::Isometry2d> truth, odometry;
  const Eigen::Isometry2d odom_frame = omnislam::slam::planar_pose(5.0, -2.0, 0.7);
  for (int i = 0; i < 12; ++i) {
    const double s = i * 0.25;
    truth.push_back(omnislam::slam::planar_pose(std::cos(s) * s, std::sin(s), 0.3 * s));
    odometry.push_back(odom_frame * omnislam::slam::planar_pose(0.02 * i, -0.01 * i, 0.01 * i) *
                       truth.back());
  }
  const Eigen::Isometry2d seam = omnislam::io::loop_seam(odometry, truth);
  const std::size_t n = truth.size();
  for (std::size_t pass = 1; pass < 4; ++pass) {
    // Within a pass the odometry's steps are the dataset's ...
    const Eigen::Isometry2d step = omnislam::io::looped_odometry(odometry, seam, pass * n + 4).inverse() *
                                   omnislam::io::looped_odometry(odometry, seam, pass * n + 5);
    CHECK(step.isApprox(odometry[4].inverse() * odometry[5], 1e-9));
    // ... and across the seam the true step from the last pose to the first.
    const Eigen::Isometry2d across = omnislam::io::looped_odometry(odometry, seam, pass * n - 1).inverse() *
                                     omnislam::io::looped_odometry(odometry, seam, pass * n);
    CHECK(across.isApprox(truth[n - 1].inverse() * truth[0], 1e-9));
  }
  CHECK(omnislam::io::looped_odometry(odometry, seam, 3).isApprox(odometry[3], 1e-12));
  // Without ground truth for every frame: the odometry jumps back to its start.
  CHECK(omnislam::io::loop_seam(odometry, {}).isApprox(Eigen::Isometry2d::Identity()));
  CHECK(omnislam::io::looped_odometry(odometry, Eigen::Isometry2d::Identity(), n + 2).isApprox(odometry[2]));
}
