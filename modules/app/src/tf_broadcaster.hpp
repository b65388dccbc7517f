#pragma once

#include <Eigen/Geometry>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "omnislam/dds/tf_publisher.hpp"
#include "omnislam/io/service_config.hpp"

namespace omnislam::app {

/// omnislamd's rt/tf (REP-105): map -> odom after every frame, from its map pose and its
/// odometry pose (and odom -> base_link when configured), then re-sent at tf.rate_hz until
/// the next frame, each stamped tf.future_dating_s ahead of the data's time. Between frames
/// the data's time advances with the steady clock from the last frame's stamp, so dataset
/// replays (stamped from 0) and live cameras (stamped with the system clock) both work.
class TfBroadcaster {
 public:
  /// `odometry`: whether the input has odometry at all (without, map -> odom is the
  /// identity and the map pose goes to odom -> base_link when that is published).
  TfBroadcaster(const dds::Participant &participant, const io::DdsSectionConfig::Tf &config, bool odometry);
  ~TfBroadcaster();
  TfBroadcaster(const TfBroadcaster &) = delete;
  TfBroadcaster &operator=(const TfBroadcaster &) = delete;

  /// A frame's result (publish thread). Without odometry the last map -> odom stays.
  void update(double stamp_s, const Eigen::Isometry2d &T_map_base,
              const std::optional<Eigen::Isometry2d> &T_odom_base);

 private:
  using Clock = std::chrono::steady_clock;
  void resend_loop(const std::stop_token &stop);
  void publish_locked(double stamp_s);

  dds::TfPublisher publisher_;
  io::DdsSectionConfig::Tf config_;
  bool odometry_ = true;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::vector<dds::FrameTransform> transforms_;  ///< the last ones sent (empty before a frame)
  double stamp_s_ = 0.0;                         ///< data time of the last frame
  bool stamped_ = false;                         ///< a frame has come
  double data_step_s_ = 0.0;                     ///< data time between the last two frames
  Clock::time_point stamped_at_;                 ///< when that frame arrived
  std::jthread thread_;
};

}  // namespace omnislam::app
