#include "replay_command.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "omnislam/io/config.hpp"
#include "omnislam/io/dataset.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/slam.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"
#include "poses.hpp"
#include "run_outputs.hpp"

namespace omnislam::app {
namespace {

struct ReplayOptions {
  std::string dataset;
  std::string config_file;
  std::string out_dir;
  std::string odometry_file;
  std::string odometry_noise;
  std::uint64_t seed = 1;
};

class StageClock {
 public:
  explicit StageClock(FrameRecord &record) : record_(record), last_(Clock::now()) {}
  void lap(std::size_t stage) {
    const auto now = Clock::now();
    record_.stage_ms[stage] = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  FrameRecord &record_;
  Clock::time_point last_;
};

// Odometry as the robot reports it (the dataset's, or a given TUM or thesis-format file),
// or the thesis noise model applied to the exact one.
std::vector<Eigen::Isometry2d> load_odometry(const io::DatasetInfo &info, const ReplayOptions &options) {
  if (!options.odometry_file.empty()) {
    const std::filesystem::path file = options.odometry_file;
    return to_isometries(file.extension() == ".txt" ? io::read_thesis_odometry(file)
                                                    : io::read_tum_file(file));
  }
  if (options.odometry_noise.empty()) return to_isometries(io::read_tum_file(info.odometry));
  return slam::apply_thesis_odometry_noise(to_isometries(io::read_tum_file(info.odometry_exact)),
                                           options.seed);
}

slam::Points2 scan_points(const stereo::LocalScan &scan) {
  slam::Points2 points;
  points.reserve(scan.points.size());
  for (const stereo::ScanPoint &p : scan.points) points.emplace_back(p.x_m, p.y_m);
  return points;
}

void run_replay(const ReplayOptions &options) {
  const io::DatasetInfo info = io::read_dataset_info(options.dataset);
  io::Config config = options.config_file.empty() ? io::Config{} : io::load_config(options.config_file);
  config.scan.camera = info.camera;  // the dataset describes its own camera and mirror
  config.scan.camera_height_m = info.camera_height_m;

  const std::vector<Eigen::Isometry2d> odometry = load_odometry(info, options);
  if (static_cast<int>(odometry.size()) < info.frames) {
    throw std::runtime_error("odometry has " + std::to_string(odometry.size()) + " poses for " +
                             std::to_string(info.frames) + " frames");
  }
  stereo::ScanReconstructor reconstructor(config.scan);
  slam::Slam slam(config.slam);
  RunRecord run;
  run.odometry_map = relative_to_first(odometry);
  run.odometry_map.resize(static_cast<std::size_t>(info.frames));
  if (!info.groundtruth.empty()) {
    run.ground_truth = relative_to_first(to_isometries(io::read_tum_file(info.groundtruth)));
    run.ground_truth.resize(static_cast<std::size_t>(info.frames));
  }
  OutputWriter writer(options.out_dir);

  stereo::LocalScan scan;
  for (int frame = 1; frame <= info.frames; ++frame) {
    FrameRecord record;
    record.t_s = (frame - 1) / info.rate_hz;
    record.T_odom_base = odometry[static_cast<std::size_t>(frame - 1)];
    StageClock clock(record);
    cv::Mat image;
    try {
      image = io::read_camera_image(info.image(frame), config.scan.camera);
    } catch (const std::exception &error) {
      std::fprintf(stderr, "omnislam replay: frame %d skipped: %s\n", frame, error.what());
      record.skipped = true;
    }
    clock.lap(0);
    scan.points.clear();
    if (!record.skipped) {
      reconstructor.unwarp(image);
      clock.lap(1);
      reconstructor.detect_edges();
      clock.lap(2);
      reconstructor.select_edges();
      clock.lap(3);
      reconstructor.match();
      clock.lap(4);
      reconstructor.triangulate(scan);
      clock.lap(5);
    }
    const slam::FrameEstimate estimate = slam.process(scan_points(scan), record.T_odom_base);
    clock.lap(6);
    record.T_map_base = estimate.T_map_base;
    record.covariance = estimate.covariance;
    record.integrated = estimate.integrated;
    record.attempt = estimate.attempt;
    record.srel_percent = estimate.registration.srel_percent;
    record.iterations = estimate.registration.iterations;
    record.scan_points = static_cast<int>(scan.points.size());
    run.frames.push_back(record);
    if (record.integrated) writer.write_thesis_map(frame, slam.map());
  }
  writer.write_all(run, slam.map(), info);
}

}  // namespace

void add_replay_command(CLI::App &app) {
  auto *command = app.add_subcommand("replay", "run the full pipeline over a dataset");
  auto options = std::make_shared<ReplayOptions>();
  command->add_option("dataset", options->dataset, "dataset directory (with dataset.yaml)")->required();
  command->add_option("--config", options->config_file, "YAML configuration");
  command->add_option("--out", options->out_dir, "output directory")->required();
  auto *odometry =
      command->add_option("--odometry", options->odometry_file,
                          "odometry file instead of the dataset's: TUM, or the thesis format (.txt)");
  command
      ->add_option("--odometry-noise", options->odometry_noise, "apply a noise model to odometry_exact.tum")
      ->check(CLI::IsMember({"thesis"}))
      ->excludes(odometry);
  command->add_option("--seed", options->seed, "seed of the odometry noise");
  command->callback([options] { run_replay(*options); });
}

}  // namespace omnislam::app
