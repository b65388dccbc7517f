#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <thread>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/pipeline/pipeline.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

// The staged pipeline on the rendered dataset against a sequential reference: the same
// stage calls in one thread, as `omnislam replay` ran before the pipeline existed.

using namespace omnislam;
using namespace std::chrono_literals;

namespace {

constexpr int kFrames = 12;  // enough for registrations, map fusion and pruning

struct Input {
  io::DatasetInfo info;
  std::vector<cv::Mat> images;
  std::vector<Eigen::Isometry2d> odometry;
  std::vector<Eigen::Isometry2d> ground_truth;
  stereo::ScanConfig scan;
};

const Input &input() {
  static const Input loaded = [] {
    // OpenCV's own worker threads (TBB) are not instrumented: under ThreadSanitizer they
    // would report races inside Canny. The pipeline's threads are what is under test.
    cv::setNumThreads(0);
    Input in;
    in.info = io::read_dataset_info(std::filesystem::path(OMNISLAM_DEFAULT_DATASETS) / "sim-room-37");
    in.scan.camera = in.info.camera;
    in.scan.camera_height_m = in.info.camera_height_m;
    in.odometry = io::to_isometries(io::read_tum_file(in.info.odometry));
    in.ground_truth = io::to_isometries(io::read_tum_file(in.info.groundtruth));
    for (int i = 1; i <= kFrames; ++i)
      in.images.push_back(io::read_camera_image(in.info.image(i), in.scan.camera));
    return in;
  }();
  return loaded;
}

struct Result {
  std::vector<slam::FrameEstimate> estimates;
  std::vector<std::size_t> scan_sizes;
  std::vector<slam::MapPoint> map;
};

Result sequential_reference(const Input &in) {
  stereo::ScanReconstructor reconstructor(in.scan);
  slam::Slam slam;
  Result result;
  stereo::LocalScan scan;
  for (int i = 0; i < kFrames; ++i) {
    reconstructor.unwarp(in.images[static_cast<std::size_t>(i)]);
    reconstructor.detect_edges();
    reconstructor.select_edges();
    reconstructor.match();
    reconstructor.triangulate(scan);
    slam::Points2 points;
    for (const stereo::ScanPoint &p : scan.points) points.emplace_back(p.x_m, p.y_m);
    result.estimates.push_back(slam.process(points, in.odometry[static_cast<std::size_t>(i)]));
    result.scan_sizes.push_back(scan.points.size());
  }
  result.map = slam.map().points();
  return result;
}

pipeline::FrameSource memory_source(const Input &in, int frames) {
  auto next = std::make_shared<int>(0);
  return [&in, frames, next]() -> pipeline::FramePtr {
    if (*next >= frames) return nullptr;
    const auto i = static_cast<std::size_t>((*next)++ % kFrames);
    auto frame = std::make_unique<pipeline::Frame>();
    frame->stamp_s = static_cast<double>(i);  // the dataset index, for the ground truth
    frame->image = in.images[i];
    frame->T_odom_base = in.odometry[i];
    frame->has_odometry = true;
    return frame;
  };
}

Result pipelined(const Input &in) {
  Result result;
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &f) {
    result.estimates.push_back(f.estimate);
    result.scan_sizes.push_back(f.scan.points.size());
  };
  pipeline::Pipeline pipeline(in.scan, {}, {}, sinks);
  pipeline.run(memory_source(in, kFrames));
  result.map = pipeline.slam().map().points();
  return result;
}

bool same_pose(const Eigen::Isometry2d &a, const Eigen::Isometry2d &b) { return a.matrix() == b.matrix(); }

}  // namespace

TEST_CASE("replay pipeline: bit-identical to the sequential run, and to itself") {
  const Input &in = input();
  const Result reference = sequential_reference(in);
  for (int run = 0; run < 2; ++run) {
    const Result result = pipelined(in);
    REQUIRE(result.estimates.size() == reference.estimates.size());
    for (std::size_t i = 0; i < reference.estimates.size(); ++i) {
      INFO("frame " << i + 1);
      CHECK(result.scan_sizes[i] == reference.scan_sizes[i]);
      CHECK(result.estimates[i].integrated == reference.estimates[i].integrated);
      CHECK(same_pose(result.estimates[i].T_map_base, reference.estimates[i].T_map_base));
      CHECK(result.estimates[i].covariance == reference.estimates[i].covariance);
    }
    REQUIRE(result.map.size() == reference.map.size());
    bool same_map = true;
    for (std::size_t i = 0; i < reference.map.size(); ++i) {
      same_map = same_map && result.map[i].position_m == reference.map[i].position_m &&
                 result.map[i].hits == reference.map[i].hits;
    }
    CHECK(same_map);
  }
}

TEST_CASE("live pipeline with a slow consumer: drops, bounded, still follows the odometry") {
  const Input &in = input();
  pipeline::PipelineConfig config;
  config.mode = pipeline::Mode::kLive;
  config.queue_capacity = 2;
  std::vector<Eigen::Isometry2d> truth_out, estimate_out;
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &f) {
    truth_out.push_back(in.ground_truth[static_cast<std::size_t>(f.stamp_s)]);
    estimate_out.push_back(f.estimate.T_map_base);
    std::this_thread::sleep_for(20ms);
  };
  pipeline::Pipeline pipeline(in.scan, {}, config, sinks);
  pipeline.run(memory_source(in, kFrames * 4));  // the dataset's 12 frames, as fast as memory gives them
  CHECK(pipeline.frames_dropped() > 0);
  CHECK(pipeline.frames_out() + pipeline.frames_dropped() == static_cast<std::uint64_t>(kFrames * 4));
  REQUIRE(truth_out.size() >= 2);
  // Map frame = the first delivered frame's pose. Frames skipped by drops (and the jumps
  // back at each loop) are bridged by the odometry, so every estimate stays near the truth.
  double max_error_m = 0.0;
  for (std::size_t i = 0; i < truth_out.size(); ++i) {
    const Eigen::Isometry2d truth_map = truth_out.front().inverse() * truth_out[i];
    max_error_m = std::max(max_error_m, (estimate_out[i].translation() - truth_map.translation()).norm());
  }
  CHECK(max_error_m < 0.1);
}
