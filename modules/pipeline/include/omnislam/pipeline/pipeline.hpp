#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "omnislam/pipeline/frame.hpp"
#include "omnislam/pipeline/loop_closer.hpp"
#include "omnislam/pipeline/profiler.hpp"
#include "omnislam/pipeline/spsc_queue.hpp"
#include "omnislam/slam/relocalizer.hpp"
#include "omnislam/slam/slam.hpp"
#include "omnislam/stereo/stereo_config.hpp"

/// @file
/// The staged real-time pipeline (architecture.md "Pipeline"): capture -> front-end
/// (unwarp, Canny, edge selection) -> stereo (DP matching, triangulation) -> SLAM ->
/// publish, one thread each, joined by bounded SPSC queues of owned frames; with
/// LoopClosureThread::kBackground a sixth thread (LoopCloser) runs the loop closure.

namespace omnislam::pipeline {

enum class Mode {
  kReplay,  ///< every queue blocks its producer: no drops, results identical to a sequential run
  kLive,    ///< capture never blocks: a frame that finds the first queue full is dropped and counted
};

/// Where loop closure (search, pose-graph solve, map rebuild) runs.
enum class LoopClosureThread {
  kByMode,      ///< kInline in Mode::kReplay, kBackground in Mode::kLive
  kInline,      ///< on the SLAM stage at each keyframe: the correction lands on that frame, deterministic
  kBackground,  ///< on a worker thread of its own; the SLAM stage takes the result at a later frame
};

struct PipelineConfig {
  Mode mode = Mode::kReplay;
  LoopClosureThread loop_closure = LoopClosureThread::kByMode;
  /// Nice value of the background loop-closure thread (0..19): at 19 a stage thread that
  /// wants the core it shares gets ~98% of it, so a search or map rebuild of a few hundred
  /// ms does not stretch the frames' latency; the worker uses what the stages leave idle.
  int loop_closure_nice = 19;
  std::size_t queue_capacity = 4;      ///< frames per queue (each holds an image: memory is bounded)
  double input_rate_hz = 0.0;          ///< capture paces the source to this rate; 0 = as fast as it delivers
  bool map_every_integration = false;  ///< attach the map to every integrated frame (thesis mapaN.txt)
  double map_period_s = 0.5;           ///< otherwise at most this often (<= 0: never)
  double profile_period_s = 1.0;       ///< profile sink period (wall clock)
  std::size_t profile_window = 300;    ///< frames in the rolling statistics
  /// Attach the SLAM state (map and its integration count) to a frame at most this often,
  /// marked Frame::state_due, for the service's snapshots (<= 0: never).
  double state_period_s = 0.0;
  /// Fault injection for the watchdog test: the stage thread with this index (1..4, see
  /// Pipeline::kThreads; 0 = none) holds the frame with sequence `stall_at_frame` until
  /// stop() is called, as a hung stage would.
  std::size_t stall_thread = 0;
  std::uint64_t stall_at_frame = 0;
};

/// Called on the capture thread for the next frame: fills stamp_s, image (or error) and
/// odometry; returns nullptr when the input is exhausted. The pipeline sets sequence and
/// the capture timings.
using FrameSource = std::function<FramePtr()>;

/// Outputs, all called on the publish thread (so they need no locking among themselves).
struct Sinks {
  std::function<void(const Frame &)> frame;              ///< every frame that got through, in order
  std::function<void(const ProfileSnapshot &)> profile;  ///< every profile_period_s and once at the end
};

class Pipeline {
 public:
  /// Builds the stage state (remap tables etc.); no thread runs before start().
  Pipeline(const stereo::ScanConfig &scan, const slam::SlamConfig &slam, PipelineConfig config, Sinks sinks);
  Pipeline(const Pipeline &) = delete;
  Pipeline &operator=(const Pipeline &) = delete;
  /// Stops and joins.
  ~Pipeline();

  /// Continues from a saved SLAM state (slam::Slam::resume, with the saved keyframe graph
  /// when there is one) instead of a new map. Only before start().
  void resume(std::vector<slam::MapPoint> points, int integrations, const Eigen::Isometry2d &T_map_base,
              const Eigen::Matrix3d &covariance, const std::optional<Eigen::Isometry2d> &T_odom_base,
              std::optional<slam::ResumedGraph> graph = {});

  /// Starts from the odometry's distance factor an earlier run learnt (a snapshot's;
  /// slam::Slam::restore_odometry_scale). Only before start().
  void restore_odometry_scale(double factor, double sigma);

  /// Starts on a saved map from an unknown pose (slam::Relocalizer): frames are searched
  /// for their pose on the map, and leave the SLAM stage with Frame::localized false until
  /// one pose is confirmed; from then on the SLAM continues from it on the saved map
  /// (slam::Slam::resume). With the map's saved keyframe graph, the SLAM continues it,
  /// unchained (slam::ResumedGraph::chained false: the pose found is not the saved one).
  /// Only before start().
  void relocalize(std::vector<slam::MapPoint> points, int integrations,
                  const slam::RelocalizerConfig &config = {}, std::optional<slam::SearchWindow> window = {},
                  std::optional<slam::KeyframeGraphState> graph = {});

  /// Starts the five threads. Call once.
  void start(FrameSource source);
  /// Asks capture to stop after the current frame; every captured frame still drains
  /// through to the sinks. Thread-safe and async-signal-safe (one atomic store).
  void stop() noexcept;
  /// Waits for the drained pipeline (the input ended or stop() was called).
  void join();
  /// start(), then join(): the whole input through the pipeline.
  void run(FrameSource source);

  /// A stage busy with one frame for longer than `limit` (a hang, for the watchdog); a
  /// stage waiting on an empty queue is not stuck. Thread-safe.
  [[nodiscard]] std::optional<std::size_t> stuck_stage(Clock::duration limit) const;

  [[nodiscard]] std::uint64_t frames_captured() const { return captured_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t frames_dropped() const { return dropped_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t frames_out() const { return out_.load(std::memory_order_relaxed); }
  /// True once the publish stage has handed on the last frame (join() will not wait). Thread-safe.
  [[nodiscard]] bool finished() const { return finished_.load(std::memory_order_acquire); }

  /// Loop jobs the background worker finished (0 with inline loop closure). Thread-safe.
  [[nodiscard]] std::uint64_t loop_jobs_done() const {
    return loop_jobs_done_.load(std::memory_order_relaxed);
  }

  /// The SLAM state. Only after join().
  [[nodiscard]] const slam::Slam &slam() const { return slam_; }
  /// The first error of the source or a sink (which ends the run early); empty if none. After join().
  [[nodiscard]] const std::string &error() const { return error_; }

  /// Names of the five threads, the indices of stuck_stage().
  static constexpr std::array<std::string_view, 5> kThreads = {"capture", "frontend", "stereo", "slam",
                                                               "publish"};

 private:
  using Queue = SpscQueue<Frame>;

  void capture_loop(FrameSource source);
  void frontend_loop();
  void stereo_loop();
  void slam_loop();
  /// One frame through the relocaliser; on the frame that confirms a pose, hands the saved
  /// map and that pose to slam_.
  void relocalize_frame(Frame &frame, const std::optional<Eigen::Isometry2d> &T_odom_base);
  /// An operator's rough pose (rt/initialpose) while relocalising: the search restarts inside
  /// the window its covariance spans.
  void narrow_search(const Frame::PoseReset &rough, const std::optional<Eigen::Isometry2d> &T_odom_base);
  void publish_loop();
  [[nodiscard]] bool take(Queue &queue, std::size_t index, FramePtr &frame);
  void forward(Queue &queue, FramePtr &frame);
  void emit_profile(const Profiler &profiler);
  void fail(std::string &slot, const std::string &message);
  void busy(std::size_t thread, bool is_busy);
  void stall_if_asked(std::size_t thread, const Frame &frame) const;

  stereo::ScanConfig scan_config_;
  PipelineConfig config_;
  Sinks sinks_;
  slam::Slam slam_;
  /// While relocalising: the search, the saved map it hands to slam_, and the search window.
  std::unique_ptr<slam::Relocalizer> relocalizer_;
  slam::RelocalizerConfig relocalizer_config_;
  std::vector<slam::MapPoint> saved_points_;
  int saved_integrations_ = 0;
  std::optional<slam::KeyframeGraphState> saved_graph_;
  std::optional<slam::SearchWindow> window_;
  std::optional<Eigen::Isometry2d> window_odometry_;  ///< odometry of the last relocalised frame
  std::array<Queue, 4> queues_;
  std::atomic<bool> stop_{false};   ///< capture stops reading
  std::atomic<bool> abort_{false};  ///< a sink failed: stop at once, discard what is queued
  std::atomic<std::uint64_t> captured_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> out_{0};
  std::atomic<bool> finished_{false};
  std::atomic<std::uint64_t> loop_jobs_done_{0};
  std::array<std::atomic<std::int64_t>, kThreads.size()> busy_since_ns_{};
  std::string capture_error_;  ///< written by capture, read after join
  std::string publish_error_;  ///< written by publish, read after join
  std::string error_;
  std::array<std::thread, kThreads.size()> threads_;
  std::unique_ptr<LoopCloser> loop_closer_;  ///< background loop closure, used by the SLAM thread only
  bool started_ = false;
};

}  // namespace omnislam::pipeline
