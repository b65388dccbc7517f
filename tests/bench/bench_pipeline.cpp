// Pipeline benchmark (not a test): throughput replaying as fast as possible from memory
// (images decoded beforehand, the dataset looped), then capture->pose latency with live
// input at 30 Hz. Run it through scripts/bench-pipeline (2 cores).
//
//   bench_pipeline [DATASET] [--loops N] [--live-seconds S] [--rate HZ] [--no-loop-closure]

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/pipeline/pipeline.hpp"

using namespace omnislam;

namespace {

struct Data {
  std::vector<cv::Mat> images;
  std::vector<Eigen::Isometry2d> odometry;
  stereo::ScanConfig scan;
};

Data load(const std::filesystem::path &dir) {
  Data data;
  const io::DatasetInfo info = io::read_dataset_info(dir);
  data.scan.camera = info.camera;
  data.scan.camera_height_m = info.camera_height_m;
  data.odometry = io::to_isometries(io::read_tum_file(info.odometry));
  for (int i = 1; i <= info.frames; ++i)
    data.images.push_back(io::read_camera_image(info.image(i), data.scan.camera));
  return data;
}

// The dataset looped: at each loop the odometry jumps back to the start, like a robot
// carried back to where it began (the map still fits).
pipeline::FrameSource looped(const Data &data, std::size_t frames) {
  auto next = std::make_shared<std::size_t>(0);
  return [&data, frames, next]() -> pipeline::FramePtr {
    if (*next >= frames) return nullptr;
    const std::size_t i = (*next)++ % data.images.size();
    auto frame = std::make_unique<pipeline::Frame>();
    frame->image = data.images[i];
    frame->T_odom_base = data.odometry[i];
    frame->has_odometry = true;
    return frame;
  };
}

}  // namespace

int main(int argc, char **argv) {
  std::filesystem::path dataset = "datasets/sim-room-37";
  int loops = 20;
  double live_seconds = 10.0, rate_hz = 30.0;
  slam::SlamConfig slam_config;  // the defaults: loop closure on
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--loops" && i + 1 < argc) {
      loops = std::atoi(argv[++i]);
    } else if (arg == "--live-seconds" && i + 1 < argc) {
      live_seconds = std::atof(argv[++i]);
    } else if (arg == "--rate" && i + 1 < argc) {
      rate_hz = std::atof(argv[++i]);
    } else if (arg == "--no-loop-closure") {
      slam_config.loop_closure.enabled = false;
    } else {
      dataset = arg;
    }
  }
  const Data data = load(dataset);

  {  // 1. Throughput: replay mode (blocking queues), input as fast as memory gives it.
    const std::size_t frames = data.images.size() * static_cast<std::size_t>(loops);
    pipeline::Pipeline pipeline(data.scan, slam_config, {}, {});
    const auto start = std::chrono::steady_clock::now();
    pipeline.run(looped(data, frames));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("throughput: %zu frames in %.3f s = %.1f frames/s (as fast as possible, from memory)\n",
                frames, seconds, static_cast<double>(frames) / seconds);
  }
  {  // 2. Latency: live mode at a camera's rate.
    pipeline::PipelineConfig config;
    config.mode = pipeline::Mode::kLive;
    config.input_rate_hz = rate_hz;
    config.profile_window = 1 << 20;
    pipeline::ProfileSnapshot profile;
    pipeline::Sinks sinks;
    sinks.profile = [&](const pipeline::ProfileSnapshot &p) { profile = p; };
    const auto frames = static_cast<std::size_t>(live_seconds * rate_hz);
    pipeline::Pipeline pipeline(data.scan, slam_config, config, sinks);
    pipeline.run(looped(data, frames));
    std::printf(
        "latency at %.0f Hz: %zu frames, capture->pose p50 %.2f ms, p99 %.2f ms, max %.2f ms; dropped %llu\n",
        rate_hz, frames, profile.latency.p50_ms, profile.latency.p99_ms, profile.latency.max_ms,
        static_cast<unsigned long long>(profile.frames_dropped));
    std::printf("stage means (ms):");
    for (std::size_t s = 0; s < pipeline::kStages.size(); ++s) {
      std::printf(" %s %.2f", std::string(pipeline::kStages[s]).c_str(), profile.stages[s].mean_ms);
    }
    std::printf("\n");
  }
  return 0;
}
