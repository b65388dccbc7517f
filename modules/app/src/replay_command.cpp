#include "replay_command.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "dataset_source.hpp"
#include "degradation_options.hpp"
#include "frame_record.hpp"
#include "omnislam/grid/trajectory_grid.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/dataset.hpp"
#include "omnislam/io/grid_files.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/io/snapshot.hpp"
#include "omnislam/pipeline/pipeline.hpp"
#include "omnislam/slam/odometry_noise.hpp"
#include "run_outputs.hpp"
#include "scan_rays.hpp"

namespace omnislam::app {
namespace {

struct ReplayOptions {
  std::string dataset;
  std::string config_file;
  std::string out_dir;
  std::string odometry_file;
  std::string odometry_noise;
  std::uint64_t seed = 1;
  std::string degrade = "none";
  std::uint64_t degrade_seed = 1;
  std::string map_file;  ///< a snapshot to localize on (--map, with --localize)
  bool localize = false;
  std::string loop_closure = "inline";  ///< where loop closure runs (--loop-closure)
  double rate_hz = 0.0;                 ///< input paced to this rate (--rate); 0: as fast as it goes
};

// Odometry as the robot reports it (the dataset's, or a given TUM or thesis-format file),
// or the thesis noise model applied to the exact one.
std::vector<Eigen::Isometry2d> load_odometry(const io::DatasetInfo &info, const ReplayOptions &options) {
  if (!options.odometry_file.empty()) {
    const std::filesystem::path file = options.odometry_file;
    return io::to_isometries(file.extension() == ".txt" ? io::read_thesis_odometry(file)
                                                        : io::read_tum_file(file));
  }
  if (options.odometry_noise.empty()) return io::to_isometries(io::read_tum_file(info.odometry));
  return slam::apply_thesis_odometry_noise(io::to_isometries(io::read_tum_file(info.odometry_exact)),
                                           options.seed);
}

void run_replay(const ReplayOptions &options, std::optional<std::uint64_t> degrade_seed) {
  const io::DatasetInfo info = io::read_dataset_info(options.dataset);
  io::Config config = options.config_file.empty() ? io::Config{} : io::load_config(options.config_file);
  config.scan.camera = info.camera;  // the dataset describes its own camera and mirror
  config.scan.camera_height_m = info.camera_height_m;

  const std::vector<Eigen::Isometry2d> odometry = load_odometry(info, options);
  if (static_cast<int>(odometry.size()) < info.frames) {
    throw std::runtime_error("odometry has " + std::to_string(odometry.size()) + " poses for " +
                             std::to_string(info.frames) + " frames");
  }
  RunRecord run;
  run.odometry_map = io::relative_to_first(odometry);
  run.odometry_map.resize(static_cast<std::size_t>(info.frames));
  if (!info.groundtruth.empty()) {
    run.ground_truth = io::relative_to_first(io::to_isometries(io::read_tum_file(info.groundtruth)));
    run.ground_truth.resize(static_cast<std::size_t>(info.frames));
  }
  OutputWriter writer(options.out_dir);

  // The service's pipeline in replay mode: blocking queues, so no frame is dropped and
  // the result equals a sequential run.
  pipeline::PipelineConfig pipeline_config;
  pipeline_config.mode = pipeline::Mode::kReplay;
  pipeline_config.map_every_integration = true;  // the thesis's mapaN.txt after every image
  // Inline (the default) keeps the run deterministic; background is the service's, for
  // measuring it (its result depends on timing).
  pipeline_config.loop_closure = options.loop_closure == "background"
                                     ? pipeline::LoopClosureThread::kBackground
                                     : pipeline::LoopClosureThread::kInline;
  pipeline_config.input_rate_hz = options.rate_hz;
  pipeline::Sinks sinks;
  // The occupancy grid of the run (map.yaml + map.pgm): the frames' boundary points and free
  // floor, built at the end from the final (optimised) poses of trajectory.tum.
  grid::TrajectoryGrid occupancy;
  sinks.frame = [&](const pipeline::Frame &frame) {
    run.frames.push_back(frame_record(frame));
    if (!frame.skipped() && frame.localized && !frame.estimate.lost && !frame.estimate.unfit)
      occupancy.add_scan(frame.estimate.trajectory_index, frame.estimate.T_map_base,
                         scan_rays(frame.scan, config.scan.camera));
    if (frame.estimate.integrated && frame.map)
      writer.write_thesis_map(static_cast<int>(frame.sequence), *frame.map);
  };
  DatasetSourceOptions source_options;
  const degrade::DegradationConfig degradation =
      degradation_for(config.degradation, options.degrade, degrade_seed);
  run.degradation_factors = degrade::enabled_factors(degradation);
  if (run.degradation_factors != "none") {
    run.degradation_seed = degradation.seed;
    source_options.degrader = std::make_shared<const degrade::Degrader>(
        degradation, cv::Size(info.camera.image_width_px, info.camera.image_height_px));
  }
  source_options.on_skip = [](int frame, const std::string &error) {
    std::fprintf(stderr, "omnislam replay: frame %d skipped: %s\n", frame, error.c_str());
  };
  if (options.localize) config.slam.localization_only = true;  // the saved map stays as it is
  pipeline::Pipeline pipeline(config.scan, config.slam, pipeline_config, std::move(sinks));
  if (options.localize) {
    io::Snapshot snapshot = io::read_snapshot(options.map_file);
    run.localizing = true;
    pipeline.relocalize(std::move(snapshot.points), snapshot.map_integrations, {}, {},
                        std::move(snapshot.graph));
    // The same wheels: what the mapping run learnt of their distance factor.
    if (snapshot.odometry_scale)
      pipeline.restore_odometry_scale(snapshot.odometry_scale->factor, snapshot.odometry_scale->sigma);
  }
  pipeline.run(dataset_source(info, odometry, config.scan.camera, std::move(source_options)));
  if (!pipeline.error().empty()) throw std::runtime_error(pipeline.error());
  writer.write_all(run, pipeline.slam().map(), info, pipeline.slam().trajectory());
  if (run.localizing) {
    const auto first =
        std::find_if(run.frames.begin(), run.frames.end(), [](const FrameRecord &f) { return f.localized; });
    if (first == run.frames.end()) {
      std::printf("not localized on %s: no pose confirmed in %zu frames (trajectory.tum has none)\n",
                  options.map_file.c_str(), run.frames.size());
    } else {
      std::printf("localized on %s at frame %td (%td frames before it have no pose)\n",
                  options.map_file.c_str(), first - run.frames.begin() + 1, first - run.frames.begin());
    }
  }
  occupancy.rebuild(pipeline.slam().trajectory());
  const grid::GridImage grid_image = occupancy.image();
  if (grid_image.width > 0)
    io::write_nav2_map(std::filesystem::path(options.out_dir) / "map.yaml", grid_image);
  // The map with the keyframe graph it was built from (its keyframes' covariances say how far
  // it may be off by place), for `omnislam map save`: a replay's files do not hold the graph.
  const std::filesystem::path snapshot_file = std::filesystem::path(options.out_dir) / "map.snapshot";
  if (auto graph = pipeline.slam().graph_state(); !graph || run.localizing) {
    std::filesystem::remove(snapshot_file);  // an earlier run's, into the same directory
  } else {
    io::Snapshot snapshot;
    snapshot.points = pipeline.slam().map().points();
    snapshot.map_integrations = pipeline.slam().map().integrations();
    snapshot.graph = std::move(graph);
    if (!pipeline.slam().trajectory().empty()) snapshot.T_map_base = pipeline.slam().trajectory().back();
    if (const slam::OdometryScale &scale = pipeline.slam().odometry_scale(); scale.sigma() > 0.0)
      snapshot.odometry_scale = io::SnapshotOdometryScale{scale.scale(), scale.sigma()};
    io::write_snapshot(snapshot_file, snapshot);
  }
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
  command
      ->add_option("--degrade", options->degrade,
                   "degrade the images as they are read: none, all, or a comma-separated list of "
                   "exposure, vignetting, dust, blur, noise, jpeg (parameters: the config's degradation:)")
      ->check(factor_list_validator())
      ->capture_default_str();
  auto *degrade_seed = command->add_option("--degrade-seed", options->degrade_seed,
                                           "seed of the image degradation (default: the config's, 1)");
  auto *map = command->add_option("--map", options->map_file, "a saved map (snapshot) to localize on");
  command
      ->add_flag(
          "--localize", options->localize,
          "start on --map from an unknown pose: search the map, confirm over several frames, then track "
          "without changing the map; frames before the pose is confirmed are left out of trajectory.tum")
      ->needs(map);
  map->needs(command->get_option("--localize"));
  command
      ->add_option("--loop-closure", options->loop_closure,
                   "where loop closure runs: inline (at each keyframe, deterministic) or background (on a "
                   "thread of its own, as omnislamd live; the result depends on timing)")
      ->check(CLI::IsMember({"inline", "background"}))
      ->capture_default_str();
  command
      ->add_option("--rate", options->rate_hz,
                   "feed the frames at this rate (Hz), as a camera would; 0: at once")
      ->check(CLI::NonNegativeNumber);
  command->callback([options, degrade_seed] {
    run_replay(*options, degrade_seed->count() > 0 ? std::optional(options->degrade_seed) : std::nullopt);
  });
}

}  // namespace omnislam::app
