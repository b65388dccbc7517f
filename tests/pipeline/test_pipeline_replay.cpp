#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <optional>
#include <thread>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/pipeline/pipeline.hpp"
#include "omnislam/slam/planar_pose.hpp"
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
    std::vector<double> range_per_px;
    for (const stereo::ScanPoint &p : scan.points) {
      points.emplace_back(p.x_m, p.y_m);
      range_per_px.push_back(p.range_per_px_m);
    }
    result.estimates.push_back(slam.process(points, in.odometry[static_cast<std::size_t>(i)], range_per_px));
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

namespace {

// Frames first..kFrames-1 from memory, the first one carrying `rough` as an operator's pose.
pipeline::FrameSource source_from(const Input &in, int first,
                                  std::optional<pipeline::Frame::PoseReset> rough) {
  auto next = std::make_shared<int>(first);
  return [&in, next, rough, first]() -> pipeline::FramePtr {
    if (*next >= kFrames) return nullptr;
    const auto i = static_cast<std::size_t>(*next);
    auto frame = std::make_unique<pipeline::Frame>();
    frame->stamp_s = static_cast<double>(i);
    frame->image = in.images[i];
    frame->T_odom_base = in.odometry[i];
    frame->has_odometry = true;
    if (rough && static_cast<int>(i) == first) frame->pose_reset = rough;
    ++*next;
    return frame;
  };
}

struct Localized {
  int frames = 0;
  int without_pose = 0;
  double worst_error_m = 0.0;
};

Localized relocalised(const Input &in, const std::vector<slam::MapPoint> &map,
                      std::optional<pipeline::Frame::PoseReset> rough = {}) {
  Localized result;
  const Eigen::Isometry2d T_truth_map = in.ground_truth.front();  // the map frame: frame 1's pose
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &f) {
    ++result.frames;
    if (!f.localized) {
      ++result.without_pose;
      return;
    }
    const Eigen::Isometry2d truth =
        T_truth_map.inverse() * in.ground_truth[static_cast<std::size_t>(f.stamp_s)];
    result.worst_error_m =
        std::max(result.worst_error_m, (truth.translation() - f.estimate.T_map_base.translation()).norm());
  };
  slam::SlamConfig slam;
  slam.localization_only = true;
  pipeline::Pipeline pipeline(in.scan, slam, {}, sinks);
  pipeline.relocalize(map, kFrames);
  pipeline.run(source_from(in, 4, rough));
  return result;
}

}  // namespace

TEST_CASE("relocalising pipeline: its pose found on a saved map, an operator's pose as a search window") {
  const Input &in = input();
  const std::vector<slam::MapPoint> map = pipelined(in).map;
  const Localized found = relocalised(in, map);
  CHECK(found.frames == kFrames - 4);
  CHECK(found.without_pose == 2);  // confirmed on the third frame
  CHECK(found.worst_error_m < 0.03);

  const Eigen::Isometry2d truth = in.ground_truth.front().inverse() * in.ground_truth[4];
  SECTION("a rough pose near the truth still finds it") {
    const Localized near = relocalised(in, map,
                                       pipeline::Frame::PoseReset{truth * slam::planar_pose(0.3, -0.2, 0.1),
                                                                  Eigen::Matrix3d::Identity() * 0.04});
    CHECK(near.without_pose == 2);
    CHECK(near.worst_error_m < 0.03);
  }
  SECTION("a rough pose whose window excludes the truth finds nothing") {
    const Localized far = relocalised(in, map,
                                      pipeline::Frame::PoseReset{truth * slam::planar_pose(1.5, 0.0, 0.0),
                                                                 Eigen::Matrix3d::Identity() * 0.01});
    CHECK(far.without_pose == kFrames - 4);
  }
}

TEST_CASE("pipeline with background loop closure: every job's result lands, none is out at the end") {
  const Input &in = input();
  pipeline::PipelineConfig config;
  config.loop_closure = pipeline::LoopClosureThread::kBackground;
  std::vector<Eigen::Isometry2d> truth_out, estimate_out;
  int keyframes = 0;
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &f) {
    truth_out.push_back(in.ground_truth[static_cast<std::size_t>(f.stamp_s)]);
    estimate_out.push_back(f.estimate.T_map_base);
    keyframes += f.estimate.keyframe ? 1 : 0;
  };
  pipeline::Pipeline pipeline(in.scan, {}, config, sinks);
  // The 12 frames looped 6 times: from the third loop on, keyframes have loop candidates.
  pipeline.run(memory_source(in, kFrames * 6));
  REQUIRE(truth_out.size() == static_cast<std::size_t>(kFrames * 6));
  CHECK(keyframes > 2);
  CHECK(pipeline.loop_jobs_done() > 0);
  CHECK_FALSE(pipeline.slam().loop_job_out());
  CHECK(pipeline.slam().trajectory().size() == truth_out.size());
  double max_error_m = 0.0;
  for (std::size_t i = 0; i < truth_out.size(); ++i) {
    const Eigen::Isometry2d truth_map = truth_out.front().inverse() * truth_out[i];
    max_error_m = std::max(max_error_m, (estimate_out[i].translation() - truth_map.translation()).norm());
  }
  CHECK(max_error_m < 0.1);
}

TEST_CASE("pipeline with background loop closure: stop() with a job in flight drains and joins") {
  const Input &in = input();
  pipeline::PipelineConfig config;
  config.mode = pipeline::Mode::kLive;  // background by mode
  std::uint64_t delivered = 0;
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &) { ++delivered; };
  pipeline::Pipeline pipeline(in.scan, {}, config, sinks);
  pipeline.start(memory_source(in, 1 << 30));  // never ends by itself
  while (pipeline.loop_jobs_done() < 2 && pipeline.frames_out() < 2000) std::this_thread::sleep_for(5ms);
  pipeline.stop();
  pipeline.join();
  CHECK(pipeline.finished());
  CHECK(pipeline.loop_jobs_done() >= 2);
  CHECK_FALSE(pipeline.slam().loop_job_out());
  CHECK(delivered == pipeline.frames_out());
}
