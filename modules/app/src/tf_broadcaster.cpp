#include "tf_broadcaster.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <exception>

namespace omnislam::app {

TfBroadcaster::TfBroadcaster(const dds::Participant &participant, const io::DdsSectionConfig::Tf &config,
                             bool odometry)
    : publisher_(participant),
      config_(config),
      odometry_(odometry),
      thread_([this](std::stop_token stop) { resend_loop(stop); }) {}

TfBroadcaster::~TfBroadcaster() {
  thread_.request_stop();
  wake_.notify_all();
}

void TfBroadcaster::update(double stamp_s, const Eigen::Isometry2d &T_map_base,
                           const std::optional<Eigen::Isometry2d> &T_odom_base) {
  std::lock_guard lock(mutex_);
  if (!odometry_) {
    // No odometry at all: odom stays on map, and the map pose is odom -> base_link.
    transforms_ = {{config_.map_frame, config_.odom_frame, Eigen::Isometry2d::Identity()}};
    if (config_.publish_odom_to_base)
      transforms_.push_back({config_.odom_frame, config_.base_frame, T_map_base});
  } else if (T_odom_base) {
    transforms_ = {{config_.map_frame, config_.odom_frame, T_map_base * T_odom_base->inverse()}};
    if (config_.publish_odom_to_base)
      transforms_.push_back({config_.odom_frame, config_.base_frame, *T_odom_base});
  }  // else a gap in the odometry: the last transforms stay
  data_step_s_ = stamped_ && stamp_s > stamp_s_ ? stamp_s - stamp_s_ : 0.0;
  stamp_s_ = stamp_s;
  stamped_ = true;
  stamped_at_ = Clock::now();
  publish_locked(stamp_s);
}

void TfBroadcaster::publish_locked(double stamp_s) {
  if (transforms_.empty()) return;
  try {
    publisher_.publish(stamp_s + config_.future_dating_s, transforms_);
  } catch (const std::exception &error) {
    spdlog::warn("{}", error.what());  // a lost TF message is not worth stopping for
  }
}

void TfBroadcaster::resend_loop(const std::stop_token &stop) {
  // Absolute deadlines: the rate holds however long a write takes.
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / config_.rate_hz));
  std::unique_lock lock(mutex_);
  for (auto deadline = Clock::now() + period; !stop.stop_requested(); deadline += period) {
    wake_.wait_until(lock, stop, deadline, [] { return false; });
    if (stop.stop_requested()) break;
    // Never past where the next frame is due (a dataset played slower than recorded would
    // otherwise send stamps beyond the next frame's, and they would run backwards); before
    // the second frame that is unknown, and re-sends repeat the frame's own stamp.
    const double elapsed_s =
        std::min(std::chrono::duration<double>(Clock::now() - stamped_at_).count(), data_step_s_);
    publish_locked(stamp_s_ + elapsed_s);
  }
}

}  // namespace omnislam::app
