// omnislamd: the real-time service (architecture.md "Service"): the staged pipeline from
// the configured input to DDS topics; systemd notification and watchdog; periodic
// snapshots of the map and pose, resumed after a restart; at shutdown, the run files.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <utility>

#include "frame_record.hpp"
#include "omnislam/dds/odometry_reader.hpp"
#include "omnislam/dds/publisher.hpp"
#include "omnislam/grid/trajectory_grid.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/grid_files.hpp"
#include "omnislam/pipeline/pipeline.hpp"
#include "omnislam/slam/planar_pose.hpp"
#include "rig_check.hpp"
#include "run_outputs.hpp"
#include "scan_rays.hpp"
#include "service_input.hpp"
#include "service_state.hpp"
#include "service_supervisor.hpp"
#include "snapshot_writer.hpp"
#include "tf_broadcaster.hpp"

namespace {

using namespace omnislam;
using namespace omnislam::app;

/// Exit codes: 2 configuration error, 3 the saved state cannot be used (a corrupt snapshot
/// under on_corrupt_snapshot: refuse, or localization without a map). The unit does not
/// restart on either: the same start would fail the same way.
constexpr int kExitConfig = 2;
constexpr int kExitState = 3;

double system_time_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

pipeline::PipelineConfig pipeline_config(const io::Config &config, double rate_hz, bool snapshots) {
  const io::PipelineSectionConfig &section = config.service.pipeline;
  pipeline::PipelineConfig result;
  result.mode = section.mode == "replay" ? pipeline::Mode::kReplay : pipeline::Mode::kLive;
  result.queue_capacity = static_cast<std::size_t>(section.queue_capacity);
  result.input_rate_hz = rate_hz;
  result.map_period_s = section.map_rate_hz > 0.0 ? 1.0 / section.map_rate_hz : 0.0;
  result.profile_period_s = section.profile_period_s;
  result.profile_window = static_cast<std::size_t>(section.profile_window);
  if (snapshots) result.state_period_s = config.persistence.snapshot_period_s;
  // Fault injection for the watchdog test (tests/python/test_omnislamd_service.py):
  // OMNISLAM_TEST_STALL=STAGE:FRAME holds that frame in that stage until shutdown.
  if (const char *stall = std::getenv("OMNISLAM_TEST_STALL")) {
    const std::string text(stall);
    const auto colon = text.find(':');
    for (std::size_t i = 1; i < pipeline::Pipeline::kThreads.size() && colon != std::string::npos; ++i) {
      if (text.substr(0, colon) == pipeline::Pipeline::kThreads[i]) {
        result.stall_thread = i;
        result.stall_at_frame = std::stoull(text.substr(colon + 1));
        spdlog::warn("OMNISLAM_TEST_STALL: the {} stage will hang on frame {}", text.substr(0, colon),
                     result.stall_at_frame);
      }
    }
  }
  return result;
}

// The first frame is taken here, before the pipeline starts, to check the rig on it; the
// source returned hands it on first. A rig off its configured centre is logged and put in
// the status (last_error) while the service runs: a knocked rig maps badly, it does not stop.
pipeline::FrameSource checked_source(pipeline::FrameSource source, const mirror::MirrorConfig &camera,
                                     dds::StatusMessage &status) {
  auto first = std::make_shared<pipeline::FramePtr>(source());
  if (*first && (*first)->error.empty() && !(*first)->image.empty()) {
    const RigCheck check = check_rig((*first)->image, camera);
    if (check.off) {
      spdlog::warn("{}", check.message);
      status.last_error = check.message;
    } else {
      spdlog::info("{}", check.message);
    }
  }
  return [first, source = std::move(source)]() mutable -> pipeline::FramePtr {
    if (*first) return std::exchange(*first, nullptr);
    return source();
  };
}

int run_service(const std::string &config_file) {
  io::Config config = io::load_config(config_file);
  const io::ServiceConfig &service = config.service;
  if (service.input.odometry == "none" && config.slam.use_odometry) {
    spdlog::info("input.odometry is none: SLAM without odometry (thesis sec. 5.2)");
    config.slam.use_odometry = false;
  }
  const std::uint64_t config_hash = io::config_file_hash(config_file);
  const std::filesystem::path snapshot_file = state_file(config.persistence);
  if (snapshot_file.empty())
    spdlog::warn("no persistence.state_dir and no STATE_DIRECTORY: the map is not saved");
  const std::optional<io::Snapshot> resumed = resume_state(config, snapshot_file, config_hash);
  // Resumed with the pose unknown (a robot carried while off): found on the saved map first.
  const io::PersistenceConfig::StartPose start_pose = config.persistence.start_pose;
  const bool search_start =
      resumed && (start_pose == io::PersistenceConfig::StartPose::kSearch ||
                  (start_pose == io::PersistenceConfig::StartPose::kAuto && config.slam.localization_only));

  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);  // before any thread (DDS, pipeline) starts

  std::optional<dds::Participant> participant;
  std::optional<dds::Publisher> publisher;
  std::optional<TfBroadcaster> tf;
  std::shared_ptr<dds::OdometryReader> odometry;
  std::shared_ptr<dds::InitialPoseReader> initial_pose;
  if (service.dds.enabled) {
    participant.emplace(dds::DdsConfig{service.dds.domain_id, service.dds.config});
    publisher.emplace(*participant);
    if (service.dds.tf.enabled) tf.emplace(*participant, service.dds.tf, service.input.odometry != "none");
    if (!service.dds.initial_pose_topic.empty())
      initial_pose = std::make_shared<dds::InitialPoseReader>(*participant, service.dds.initial_pose_topic);
    if (service.input.odometry == "dds") {
      odometry = std::make_shared<dds::OdometryReader>(
          *participant, service.input.odometry_topic,
          dds::OdometryLookup{service.input.odometry_max_extrapolation_s, service.input.odometry_max_gap_s});
    }
  }
  dds::StatusMessage status{system_time_s(), dds::ServiceState::kStarting, 0, 0, 0, ""};
  if (publisher) publisher->status(status);

  // A dataset input continues after the snapshot's frame when the saved pose is taken as is;
  // a robot whose pose is searched for may be anywhere in it.
  const ServiceInput input = make_service_input(
      config, odometry, resumed && !search_start ? resumed->t_s : -std::numeric_limits<double>::infinity());
  spdlog::info("input: {}, {} Hz, mode {}, DDS domain {}", input.description, input.rate_hz,
               service.pipeline.mode, service.dds.enabled ? std::to_string(service.dds.domain_id) : "off");
  if (publisher && service.dds.wait_for_subscribers > 0 &&
      !publisher->wait_for_readers(service.dds.wait_for_subscribers, service.dds.wait_timeout_s)) {
    spdlog::warn("fewer than {} pose subscribers after {} s; starting anyway",
                 service.dds.wait_for_subscribers, service.dds.wait_timeout_s);
  }

  std::optional<SnapshotWriter> snapshots;
  if (!snapshot_file.empty()) {
    std::filesystem::create_directories(snapshot_file.parent_path());
    snapshots.emplace(snapshot_file);
  }
  FrameCounts counts;
  if (resumed) counts.totals = resumed->counters;
  const bool expects_odometry = service.input.odometry != "none";

  RunRecord run;
  bool posed = !search_start;  // a frame has had a pose (set by the publish thread; read after join)
  std::uint64_t not_localized = 0;
  std::optional<std::uint64_t> lost_at;  // the frame the tracking was lost at, until found again
  std::uint64_t lost_frames = 0;
  std::optional<std::uint64_t> doubt_at;  // the first frame of a run of misfits, until the map fits again
  std::uint64_t doubt_frames = 0;
  // rt/map, snapshots, and map.yaml + map.pgm in output_dir; rebuilt when a loop closure
  // corrects the poses it was built with.
  grid::TrajectoryGrid occupancy;
  if (resumed && resumed->grid) {
    if (std::abs(resumed->grid->resolution_m - occupancy.config().resolution_m) < 1e-9)
      occupancy.seed(*resumed->grid);
    else
      spdlog::warn("the snapshot's occupancy grid has {} m cells, not {} m: the grid starts empty",
                   resumed->grid->resolution_m, occupancy.config().resolution_m);
  }
  std::optional<FrameRecord> last_frame;  // for the final snapshot
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &frame) {
    io::SnapshotCounters &n = counts.totals;
    ++n.frames;
    n.dropped += frame.dropped_before;
    if (frame.skipped()) {
      ++n.skipped;
      counts.skipped.fetch_add(1, std::memory_order_relaxed);
      spdlog::warn("frame {} skipped: {}", frame.sequence, frame.error);
    }
    (frame.estimate.integrated ? n.integrated : n.not_integrated) += 1;
    if (expects_odometry && !frame.has_odometry) {
      counts.without_odometry.fetch_add(1, std::memory_order_relaxed);
      if (!counts.in_odometry_gap) {
        spdlog::warn(
            "frame {} (t {:.3f} s) has no odometry ({} has no sample close enough): predicted with "
            "the last motion, not added to the map, until odometry returns",
            frame.sequence, frame.stamp_s, service.input.odometry_topic);
      }
      counts.in_odometry_gap = true;
    } else if (counts.in_odometry_gap && frame.has_odometry) {
      spdlog::info("odometry is back at frame {}", frame.sequence);
      counts.in_odometry_gap = false;
    }
    if (frame.dropped_before > 0)
      spdlog::debug("{} frames dropped before frame {}", frame.dropped_before, frame.sequence);
    if (frame.estimate.lost) {  // no pose published until the robot is found on the map again
      if (!lost_at) {
        lost_at = frame.sequence;
        const std::string message = fmt::format(
            "tracking lost at frame {}: the scans do not fit the map where odometry puts them "
            "(slam.lost_after_frames); searching the whole map, nothing published or mapped until found",
            frame.sequence);
        spdlog::warn("{}", message);
        if (publisher)
          publisher->status({system_time_s(), dds::ServiceState::kLocalizing, frame.sequence, 0, 0, message});
      }
      ++lost_frames;
      return;
    }
    if (frame.estimate.unfit) {
      // In doubt: the scan contradicts the map where odometry puts it (carried off, or
      // something right in front of the camera). Its pose is that guess, which the scans
      // speak against: not published, nor tf (map -> odom keeps its last, so odom -> base
      // dead-reckons meanwhile), nor saved, until the map fits or the search confirms a pose.
      if (!doubt_at) {
        doubt_at = frame.sequence;
        spdlog::info("frame {} does not fit the map where odometry puts it: pose withheld until a scan fits",
                     frame.sequence);
      }
      ++doubt_frames;
      if (publisher) publisher->scan(frame.stamp_s, frame.scan);
      return;
    }
    if (doubt_at && !lost_at) {
      spdlog::info("frame {} fits the map again (in doubt since frame {})", frame.sequence, *doubt_at);
    }
    doubt_at.reset();
    if (!frame.localized) {  // no pose yet: nothing to publish, grid or save
      ++not_localized;
      return;
    }
    if (lost_at) {
      spdlog::info("found again at frame {} (lost since frame {}): x {:.3f} m, y {:.3f} m, yaw {:.1f} deg",
                   frame.sequence, *lost_at, frame.estimate.T_map_base.translation().x(),
                   frame.estimate.T_map_base.translation().y(),
                   slam::yaw_rad_of(frame.estimate.T_map_base) * 180.0 / std::numbers::pi);
      lost_at.reset();
      if (publisher)
        publisher->status({system_time_s(), dds::ServiceState::kRunning, frame.sequence, 0, 0, ""});
    }
    if (!posed) {
      posed = true;
      spdlog::info(
          "localized on the saved map at frame {} after {} frames: x {:.3f} m, y {:.3f} m, yaw {:.1f} deg",
          frame.sequence, not_localized, frame.estimate.T_map_base.translation().x(),
          frame.estimate.T_map_base.translation().y(),
          slam::yaw_rad_of(frame.estimate.T_map_base) * 180.0 / std::numbers::pi);
      if (publisher)
        publisher->status({system_time_s(), dds::ServiceState::kRunning, frame.sequence, 0, 0, ""});
    }
    const bool gridded = publisher || !service.output_dir.empty() || snapshots;
    if (gridded && frame.trajectory) occupancy.rebuild(*frame.trajectory);
    // Kept for the rebuilds after loop closures only where the SLAM keeps the frame's scan
    // for its own (bounded per keyframe): a place driven through again and again grows neither.
    if (gridded && !frame.skipped() && !frame.estimate.unfit)
      occupancy.add_scan(frame.estimate.trajectory_index, frame.estimate.T_map_base,
                         scan_rays(frame.scan, config.scan.camera),
                         config.slam.loop_closure.enabled && frame.estimate.mapped);
    if (tf)
      tf->update(frame.stamp_s, frame.estimate.T_map_base,
                 frame.has_odometry ? std::optional(frame.T_odom_base) : std::nullopt);
    if (publisher) {
      publisher->pose(frame.stamp_s, frame.estimate.T_map_base, frame.estimate.covariance);
      publisher->scan(frame.stamp_s, frame.scan);
      if (frame.map) {  // the point map and the occupancy grid, at pipeline.map_rate_hz
        publisher->map(frame.stamp_s, *frame.map);
        if (const grid::GridImage image = occupancy.image(); image.width > 0)
          publisher->grid(frame.stamp_s, image);
      }
    }
    if (frame.map) counts.map_points.store(frame.map->size(), std::memory_order_relaxed);
    last_frame = frame_record(frame);
    if (frame.state_due && snapshots)
      snapshots->submit(make_snapshot(*last_frame, *frame.map, frame.map_integrations, n, config_hash,
                                      occupancy.image(),
                                      frame.graph ? std::optional(*frame.graph) : std::nullopt));
    if (!service.output_dir.empty()) run.frames.push_back(*last_frame);
  };
  sinks.profile = [&](const pipeline::ProfileSnapshot &profile) {
    if (publisher) publisher->profile(system_time_s(), profile);
    spdlog::info("frames in {} out {} dropped {}; latency p50 {:.1f} ms p99 {:.1f} ms; map {} points",
                 profile.frames_captured, profile.frames_out, profile.frames_dropped, profile.latency.p50_ms,
                 profile.latency.p99_ms, counts.map_points.load(std::memory_order_relaxed));
  };

  pipeline::Pipeline pipeline(config.scan, config.slam,
                              pipeline_config(config, input.rate_hz, snapshots.has_value()),
                              std::move(sinks));
  if (search_start) {
    spdlog::info(
        "searching for the pose on the saved map ({} points; persistence.start_pose {}): nothing is "
        "published until one pose is confirmed",
        resumed->points.size(), config.slam.localization_only ? "auto, localization_only" : "search");
    pipeline.relocalize(resumed->points, resumed->map_integrations, {}, {}, resumed->graph);
    status.state = dds::ServiceState::kLocalizing;  // running becomes the publish thread's to say
    status.stamp_s = system_time_s();
    if (publisher) publisher->status(status);
  } else if (resumed) {
    pipeline.resume(resumed->points, resumed->map_integrations, resumed->T_map_base, resumed->covariance,
                    resumed->T_odom_base, resumed_graph(*resumed));
  }
  if (resumed && resumed->odometry_scale) {  // the same wheels: what the saved run learnt of them
    pipeline.restore_odometry_scale(resumed->odometry_scale->factor, resumed->odometry_scale->sigma);
    spdlog::info("odometry distance factor from the snapshot: {:.4f} +- {:.4f}",
                 resumed->odometry_scale->factor, resumed->odometry_scale->sigma);
  }
  const auto initial_pose_counts = std::make_shared<InitialPoseCounts>();
  pipeline::FrameSource source = checked_source(input.source, config.scan.camera, status);
  if (initial_pose)
    source =
        with_initial_pose(std::move(source), initial_pose, service.dds.tf.map_frame, initial_pose_counts);
  pipeline.start(std::move(source));
  if (!search_start) {
    status.state = dds::ServiceState::kRunning;
    status.stamp_s = system_time_s();
    if (publisher) publisher->status(status);
  }
  const SystemdNotifier notifier;
  // systemd's STATUS line carries the rig check's warning too (systemctl status shows it).
  notifier.ready("running: " + input.description +
                 (status.last_error.empty() ? "" : "; " + status.last_error));

  const bool signalled = supervise(pipeline, signals, notifier, service.stage_timeout_s, counts);
  notifier.stopping(signalled ? "stopping: draining the pipeline" : "stopping: the input ended");
  if (signalled) {
    status.state = dds::ServiceState::kStopping;
    status.stamp_s = system_time_s();
    if (publisher) publisher->status(status);
  }
  pipeline.stop();
  pipeline.join();

  status.stamp_s = system_time_s();
  status.frames_in = pipeline.frames_captured();
  status.frames_out = pipeline.frames_out();
  status.frames_dropped = pipeline.frames_dropped();
  status.last_error = pipeline.error();
  if (status.last_error.empty()) status.last_error = initial_pose_counts->last_error();
  status.state = pipeline.error().empty() ? dds::ServiceState::kStopped : dds::ServiceState::kFailed;
  const double last_stamp = last_frame ? last_frame->t_s : status.stamp_s;
  occupancy.rebuild(pipeline.slam().trajectory());       // at the final poses, as trajectory.tum
  const grid::GridImage final_grid = occupancy.image();  // empty when nothing was gridded
  if (snapshots && last_frame) {
    // The final state, written before anything else can fail.
    snapshots->submit(make_snapshot(*last_frame, pipeline.slam().map().points(),
                                    pipeline.slam().map().integrations(), counts.totals, config_hash,
                                    final_grid, pipeline.slam().graph_state()));
  }
  if (snapshots) {
    snapshots->finish();
    if (!snapshots->last_error().empty()) status.last_error = snapshots->last_error();
    spdlog::info("{} snapshots written to {}", snapshots->written(), snapshots->file().string());
  }
  if (publisher) {
    if (posed) publisher->map(last_stamp, pipeline.slam().map().points());  // the final state
    if (final_grid.width > 0) publisher->grid(last_stamp, final_grid);
    publisher->status(status);
    publisher->flush(2.0);
  }
  if (!service.output_dir.empty()) {
    io::DatasetInfo info;
    info.name = "omnislamd";
    for (const FrameRecord &f : run.frames)
      run.odometry_map.push_back(run.frames.front().T_odom_base.inverse() * f.T_odom_base);
    OutputWriter(service.output_dir)
        .write_all(run, pipeline.slam().map(), info, pipeline.slam().trajectory());
    if (final_grid.width > 0)
      io::write_nav2_map(std::filesystem::path(service.output_dir) / "map.yaml", final_grid);
  }
  if (initial_pose) {
    spdlog::info("{} initial poses on {} applied, {} in another frame ignored, {} non-finite dropped",
                 initial_pose_counts->applied.load(), service.dds.initial_pose_topic,
                 initial_pose_counts->rejected.load(), initial_pose->rejected());
  }
  if (odometry && odometry->rejected() > 0)
    spdlog::warn("{} odometry samples on {} had a non-finite stamp or pose and were dropped",
                 odometry->rejected(), service.input.odometry_topic);
  spdlog::info("stopped: {} frames in, {} out, {} dropped, {} skipped, {} without odometry", status.frames_in,
               status.frames_out, status.frames_dropped, counts.skipped.load(),
               counts.without_odometry.load());
  if (search_start && posed)
    spdlog::info("{} frames before the pose was found on the saved map", not_localized);
  if (search_start && !posed)
    spdlog::warn("{} frames and no pose found on the saved map (it is kept unchanged)", not_localized);
  if (doubt_frames > 0)
    spdlog::info("{} frames in doubt before a fit or a loss (pose withheld)", doubt_frames);
  if (lost_frames > 0) {
    spdlog::info("{} frames without a pose while the tracking was lost{}", lost_frames,
                 lost_at ? fmt::format(" (lost since frame {} at the end)", *lost_at) : std::string());
  }
  if (!pipeline.error().empty()) {
    spdlog::error("{}", pipeline.error());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App app{"omnislamd: omnidirectional stereo SLAM service"};
  std::string config_file;
  app.add_option("--config", config_file, "YAML configuration (deploy/omnislamd.yaml)")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &error) {
    return app.exit(error);
  }
  try {
    return run_service(config_file);
  } catch (const io::ConfigError &error) {
    spdlog::critical("configuration error: {}", error.what());
    return kExitConfig;
  } catch (const StateError &error) {
    spdlog::critical("cannot start from the saved state: {}", error.what());
    return kExitState;
  } catch (const std::exception &error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
}
