#include "omnislam/pipeline/pipeline.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include <exception>
#include <utility>

#include <opencv2/core/utility.hpp>

#include "omnislam/stereo/scan_reconstructor.hpp"

namespace omnislam::pipeline {
namespace {

constexpr std::size_t kFrontend = 0, kStereo = 1, kSlamQueue = 2, kPublish = 3;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// Times consecutive steps of one frame into its stage_ms.
class StepClock {
 public:
  explicit StepClock(Frame &frame) : frame_(frame), last_(Clock::now()) {}
  void lap(Step step) {
    const auto now = Clock::now();
    frame_.timings.stage_ms[step] = ms_between(last_, now);
    last_ = now;
  }

 private:
  Frame &frame_;
  Clock::time_point last_;
};

slam::Points2 scan_points(const stereo::LocalScan &scan) {
  slam::Points2 points;
  points.reserve(scan.points.size());
  for (const stereo::ScanPoint &p : scan.points) points.emplace_back(p.x_m, p.y_m);
  return points;
}

std::vector<double> scan_range_per_px(const stereo::LocalScan &scan) {
  std::vector<double> ranges;
  ranges.reserve(scan.points.size());
  for (const stereo::ScanPoint &p : scan.points) ranges.push_back(p.range_per_px_m);
  return ranges;
}

bool background_loop_closure(const PipelineConfig &config) {
  switch (config.loop_closure) {
    case LoopClosureThread::kInline:
      return false;
    case LoopClosureThread::kBackground:
      return true;
    case LoopClosureThread::kByMode:
      break;
  }
  return config.mode == Mode::kLive;
}

slam::SlamConfig with_loop_closure_thread(slam::SlamConfig slam, const PipelineConfig &config) {
  slam.loop_closure.background = slam.loop_closure.enabled && background_loop_closure(config);
  return slam;
}

}  // namespace

Pipeline::Pipeline(const stereo::ScanConfig &scan, const slam::SlamConfig &slam, PipelineConfig config,
                   Sinks sinks)
    : scan_config_(scan),
      config_(config),
      sinks_(std::move(sinks)),
      slam_(with_loop_closure_thread(slam, config)),
      queues_{Queue(config.queue_capacity), Queue(config.queue_capacity), Queue(config.queue_capacity),
              Queue(config.queue_capacity)} {}

Pipeline::~Pipeline() {
  stop();
  join();
}

void Pipeline::resume(std::vector<slam::MapPoint> points, int integrations,
                      const Eigen::Isometry2d &T_map_base, const Eigen::Matrix3d &covariance,
                      const std::optional<Eigen::Isometry2d> &T_odom_base,
                      std::optional<slam::ResumedGraph> graph) {
  if (started_) throw std::logic_error("Pipeline::resume after start");
  slam_.resume(std::move(points), integrations, T_map_base, covariance, T_odom_base, std::move(graph));
}

void Pipeline::restore_odometry_scale(double factor, double sigma) {
  if (started_) throw std::logic_error("Pipeline::restore_odometry_scale after start");
  slam_.restore_odometry_scale(factor, sigma);
}

void Pipeline::relocalize(std::vector<slam::MapPoint> points, int integrations,
                          const slam::RelocalizerConfig &config, std::optional<slam::SearchWindow> window,
                          std::optional<slam::KeyframeGraphState> graph) {
  if (started_) throw std::logic_error("Pipeline::relocalize after start");
  relocalizer_ = std::make_unique<slam::Relocalizer>(slam::positions_of(points), config);
  relocalizer_config_ = config;
  saved_points_ = std::move(points);
  saved_integrations_ = integrations;
  saved_graph_ = std::move(graph);
  window_ = window;
}

void Pipeline::start(FrameSource source) {
  if (started_) throw std::logic_error("Pipeline::start called twice");
  started_ = true;
  // One thread per stage is the parallelism: OpenCV's own worker pool would only compete
  // with the stages for the cores (and, uninstrumented, hides its work from TSan). Canny and
  // remap give the same pixels either way.
  cv::setNumThreads(0);
  if (with_loop_closure_thread({}, config_).loop_closure.background)
    loop_closer_ = std::make_unique<LoopCloser>(config_.loop_closure_nice);
  threads_[0] =
      std::thread([this, source = std::move(source)]() mutable { capture_loop(std::move(source)); });
  threads_[1] = std::thread([this] { frontend_loop(); });
  threads_[2] = std::thread([this] { stereo_loop(); });
  threads_[3] = std::thread([this] { slam_loop(); });
  threads_[4] = std::thread([this] { publish_loop(); });
}

void Pipeline::stop() noexcept { stop_.store(true, std::memory_order_relaxed); }

void Pipeline::join() {
  for (std::thread &thread : threads_) {
    if (thread.joinable()) thread.join();
  }
  loop_closer_.reset();  // the SLAM thread, its only user, has ended
  error_ = !capture_error_.empty() ? capture_error_ : publish_error_;
}

void Pipeline::run(FrameSource source) {
  start(std::move(source));
  join();
}

std::optional<std::size_t> Pipeline::stuck_stage(Clock::duration limit) const {
  const std::int64_t now = now_ns();
  const std::int64_t limit_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(limit).count();
  for (std::size_t i = 0; i < busy_since_ns_.size(); ++i) {
    const std::int64_t since = busy_since_ns_[i].load(std::memory_order_relaxed);
    if (since != 0 && now - since > limit_ns) return i;
  }
  return std::nullopt;
}

void Pipeline::busy(std::size_t thread, bool is_busy) {
  busy_since_ns_[thread].store(is_busy ? now_ns() : 0, std::memory_order_relaxed);
}

void Pipeline::stall_if_asked(std::size_t thread, const Frame &frame) const {
  if (thread != config_.stall_thread || frame.sequence != config_.stall_at_frame) return;
  while (!stop_.load(std::memory_order_relaxed)) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

void Pipeline::fail(std::string &slot, const std::string &message) {
  if (slot.empty()) slot = message;
  abort_.store(true, std::memory_order_relaxed);
  stop_.store(true, std::memory_order_relaxed);
}

bool Pipeline::take(Queue &queue, std::size_t index, FramePtr &frame) {
  if (queue.pop(frame) != PopStatus::kItem) return false;
  frame->timings.wait_ms[index] = ms_between(frame->enqueued, Clock::now());
  frame->timings.queue_depth[index] = static_cast<int>(queue.size_for_consumer());
  return true;
}

// Downstream of capture every queue blocks its producer (in live mode too): the drop
// policy acts at capture only, so a slow stage backs the queues up until capture drops.
void Pipeline::forward(Queue &queue, FramePtr &frame) {
  frame->enqueued = Clock::now();
  if (!queue.push(frame, abort_)) frame.reset();  // aborting: discard
}

void Pipeline::capture_loop(FrameSource source) {
  Queue &out = queues_[kFrontend];
  const Clock::time_point start = Clock::now();
  std::uint64_t sequence = 0;
  std::uint32_t dropped_run = 0;
  std::optional<Frame::PoseReset> carried_reset;
  while (!stop_.load(std::memory_order_relaxed)) {
    if (config_.input_rate_hz > 0.0) {
      const auto due = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                   static_cast<double>(sequence) / config_.input_rate_hz));
      // Sleep in slices so that stop() is noticed at low rates too.
      while (Clock::now() < due && !stop_.load(std::memory_order_relaxed)) {
        std::this_thread::sleep_until(std::min(due, Clock::now() + std::chrono::milliseconds(20)));
      }
      if (stop_.load(std::memory_order_relaxed)) break;
    }
    busy(0, true);
    const Clock::time_point before = Clock::now();
    FramePtr frame;
    try {
      frame = source();
    } catch (const std::exception &error) {
      fail(capture_error_, std::string("input: ") + error.what());
    }
    busy(0, false);
    if (!frame) break;
    frame->captured = Clock::now();
    frame->sequence = ++sequence;
    frame->timings.stage_ms[kRead] = ms_between(before, frame->captured);
    frame->dropped_before = dropped_run;
    if (!frame->pose_reset) frame->pose_reset = std::move(carried_reset);  // a dropped frame's
    carried_reset.reset();
    frame->enqueued = frame->captured;
    captured_.fetch_add(1, std::memory_order_relaxed);
    if (config_.mode == Mode::kLive) {
      if (!out.try_push(frame)) {
        carried_reset = std::move(frame->pose_reset);
        ++dropped_run;
        dropped_.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
    } else if (!out.push(frame, abort_)) {
      break;
    }
    dropped_run = 0;
  }
  out.close();
}

void Pipeline::frontend_loop() {
  stereo::ScanReconstructor frontend(scan_config_);
  FramePtr frame;
  while (take(queues_[kFrontend], kFrontend, frame)) {
    busy(1, true);
    stall_if_asked(1, *frame);
    if (!frame->skipped() && !frontend.accepts(frame->image)) {
      frame->error = "not an 8-bit grey image of the camera size";
    }
    if (!frame->skipped()) {
      StepClock clock(*frame);
      frontend.unwarp(frame->image);
      clock.lap(kUnwarp);
      frontend.detect_edges();
      clock.lap(kCanny);
      frontend.select_edges();
      clock.lap(kEdges);
      frontend.swap_lobes(frame->inner, frame->outer);
    }
    frame->image.release();
    busy(1, false);
    forward(queues_[kStereo], frame);
  }
  queues_[kStereo].close();
}

void Pipeline::stereo_loop() {
  stereo::ScanReconstructor matcher(scan_config_);
  FramePtr frame;
  while (take(queues_[kStereo], kStereo, frame)) {
    busy(2, true);
    stall_if_asked(2, *frame);
    if (!frame->skipped()) {
      StepClock clock(*frame);
      matcher.swap_lobes(frame->inner, frame->outer);
      matcher.match();
      clock.lap(kMatch);
      matcher.triangulate(frame->scan);
      clock.lap(kTriangulation);
    }
    frame->inner = {};  // the lobes are not needed downstream
    frame->outer = {};
    busy(2, false);
    forward(queues_[kSlamQueue], frame);
  }
  queues_[kSlamQueue].close();
}

void Pipeline::narrow_search(const Frame::PoseReset &rough,
                             const std::optional<Eigen::Isometry2d> &T_odom_base) {
  // Three standard deviations of the rough pose, never less than what the relocaliser takes
  // for one and the same pose.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> position(rough.covariance.topLeftCorner<2, 2>());
  const double sigma_m = std::sqrt(std::max(0.0, position.eigenvalues().maxCoeff()));
  const double sigma_rad = std::sqrt(std::max(0.0, rough.covariance(2, 2)));
  window_ = slam::SearchWindow{rough.T_map_base, std::max(3.0 * sigma_m, relocalizer_config_.distinct_m),
                               std::max(3.0 * sigma_rad, relocalizer_config_.distinct_rad)};
  window_odometry_ = T_odom_base;
  relocalizer_->reset();
}

void Pipeline::relocalize_frame(Frame &frame, const std::optional<Eigen::Isometry2d> &T_odom_base) {
  // The window travels with the robot: its centre follows the odometry since the last frame.
  if (window_ && T_odom_base && window_odometry_) {
    window_->T_map_base = window_->T_map_base * (window_odometry_->inverse() * *T_odom_base);
  }
  if (T_odom_base) window_odometry_ = T_odom_base;
  const slam::LocalizationResult found = relocalizer_->process(scan_points(frame.scan), T_odom_base, window_);
  frame.localized = found.state == slam::LocalizationState::kLocalized;
  if (!frame.localized) return;
  frame.estimate.T_map_base = found.T_map_base;
  frame.estimate.covariance = found.covariance;
  std::optional<slam::ResumedGraph> graph;
  if (saved_graph_) graph = slam::ResumedGraph{std::move(*saved_graph_), false};
  slam_.resume(std::move(saved_points_), saved_integrations_, found.T_map_base, found.covariance, T_odom_base,
               std::move(graph));
  // The pose found on the saved map is as uncertain as the map is there, too
  // (Slam::map_uncertainty_at; Slam::resume starts its walk from the same).
  frame.estimate.covariance += slam_.map_uncertainty_at(found.T_map_base);
  relocalizer_.reset();
}

void Pipeline::slam_loop() {
  Clock::time_point last_map = Clock::time_point::min();
  Clock::time_point last_state = Clock::now();
  FramePtr frame;
  while (take(queues_[kSlamQueue], kSlamQueue, frame)) {
    busy(3, true);
    stall_if_asked(3, *frame);
    StepClock clock(*frame);
    const auto odometry = frame->has_odometry ? std::optional(frame->T_odom_base) : std::nullopt;
    if (relocalizer_) {
      // An operator's pose while the pose is searched for: a search window, not the answer.
      if (frame->pose_reset) narrow_search(*frame->pose_reset, odometry);
      relocalize_frame(*frame, odometry);
    } else {
      // Background loop closure: a finished job's correction reaches this frame's
      // prediction, and a new keyframe's job leaves with it.
      if (loop_closer_) {
        while (std::optional<slam::LoopResult> result = loop_closer_->try_take())
          slam_.apply_loop_result(std::move(*result));
      }
      if (frame->pose_reset) slam_.set_pose(frame->pose_reset->T_map_base, frame->pose_reset->covariance);
      frame->estimate = slam_.process(scan_points(frame->scan), odometry, scan_range_per_px(frame->scan));
      if (loop_closer_) {
        if (std::optional<slam::LoopJob> job = slam_.take_loop_job()) loop_closer_->submit(std::move(*job));
        loop_jobs_done_.store(loop_closer_->jobs_done(), std::memory_order_relaxed);
      }
    }
    clock.lap(kSlam);
    const Clock::time_point now = Clock::now();
    if (frame->estimate.integrated) {
      const bool due = config_.map_period_s > 0.0 &&
                       (last_map == Clock::time_point::min() ||
                        now - last_map >= std::chrono::duration<double>(config_.map_period_s));
      // A loop closure rebuilt the map: publish the corrected one now.
      if (config_.map_every_integration || due || frame->estimate.map_rebuilt) {
        frame->map = std::make_shared<const std::vector<slam::MapPoint>>(slam_.map().points());
        last_map = now;
      }
      if (frame->estimate.map_rebuilt)
        frame->trajectory = std::make_shared<const std::vector<Eigen::Isometry2d>>(slam_.trajectory());
    }
    if (config_.state_period_s > 0.0 &&
        now - last_state >= std::chrono::duration<double>(config_.state_period_s)) {
      if (!frame->map) frame->map = std::make_shared<const std::vector<slam::MapPoint>>(slam_.map().points());
      frame->state_due = true;
      if (std::optional<slam::KeyframeGraphState> graph = slam_.graph_state())
        frame->graph = std::make_shared<const slam::KeyframeGraphState>(std::move(*graph));
      last_state = now;
    }
    if (frame->map) frame->map_integrations = slam_.map().integrations();
    busy(3, false);
    forward(queues_[kPublish], frame);
  }
  // The job out at the end, and the search of the newest keyframe if it waited for it,
  // still reach the final graph, trajectory and map.
  while (loop_closer_) {
    if (std::optional<slam::LoopJob> job = slam_.take_loop_job()) loop_closer_->submit(std::move(*job));
    if (!slam_.loop_job_out()) break;
    std::optional<slam::LoopResult> result = loop_closer_->wait_take();
    if (!result) break;
    slam_.apply_loop_result(std::move(*result));
  }
  if (loop_closer_) loop_jobs_done_.store(loop_closer_->jobs_done(), std::memory_order_relaxed);
  queues_[kPublish].close();
}

void Pipeline::emit_profile(const Profiler &profiler) {
  if (!sinks_.profile) return;
  ProfileSnapshot snapshot = profiler.snapshot();
  snapshot.frames_captured = frames_captured();
  snapshot.frames_dropped = frames_dropped();
  snapshot.frames_out = frames_out();
  for (std::size_t q = 0; q < queues_.size(); ++q)
    snapshot.queue_capacity[q] = static_cast<int>(queues_[q].capacity());
  sinks_.profile(snapshot);
}

void Pipeline::publish_loop() {
  Queue &in = queues_[kPublish];
  Profiler profiler(config_.profile_window);
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(config_.profile_period_s > 0.0 ? config_.profile_period_s : 1.0));
  Clock::time_point next_profile = Clock::now() + period;
  for (;;) {
    FramePtr frame;
    const PopStatus status = in.pop(frame, next_profile);
    if (status == PopStatus::kClosed) break;
    if (status == PopStatus::kItem && !abort_.load(std::memory_order_relaxed)) {
      const Clock::time_point now = Clock::now();
      frame->timings.wait_ms[kPublish] = ms_between(frame->enqueued, now);
      frame->timings.queue_depth[kPublish] = static_cast<int>(in.size_for_consumer());
      frame->timings.latency_ms = ms_between(frame->captured, now);
      profiler.add(frame->timings);
      busy(4, true);
      stall_if_asked(4, *frame);
      try {
        if (sinks_.frame) sinks_.frame(*frame);
      } catch (const std::exception &error) {
        fail(publish_error_, std::string("output: ") + error.what());
      }
      busy(4, false);
      out_.fetch_add(1, std::memory_order_relaxed);
    }
    if (Clock::now() >= next_profile) {
      next_profile += period;
      try {
        emit_profile(profiler);
      } catch (const std::exception &error) {
        fail(publish_error_, std::string("profile output: ") + error.what());
      }
    }
  }
  try {
    emit_profile(profiler);
  } catch (const std::exception &error) {
    fail(publish_error_, std::string("profile output: ") + error.what());
  }
  finished_.store(true, std::memory_order_release);
}

}  // namespace omnislam::pipeline
