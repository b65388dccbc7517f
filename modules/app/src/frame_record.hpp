#pragma once

#include "omnislam/pipeline/frame.hpp"
#include "run_record.hpp"

namespace omnislam::app {

/// What the run files keep of a frame that went through the pipeline.
[[nodiscard]] inline FrameRecord frame_record(const pipeline::Frame &frame) {
  FrameRecord record;
  record.t_s = frame.stamp_s;
  record.T_map_base = frame.estimate.T_map_base;
  record.T_odom_base = frame.T_odom_base;
  record.has_odometry = frame.has_odometry;
  record.covariance = frame.estimate.covariance;
  record.skipped = frame.skipped();
  record.integrated = frame.estimate.integrated;
  record.localized = frame.localized;
  record.lost = frame.estimate.lost;
  record.relocalized = frame.estimate.relocalized;
  record.keyframe = frame.estimate.keyframe;
  record.revisit = frame.estimate.revisit;
  record.mapped = frame.estimate.mapped;
  record.loop_closed = frame.estimate.loop_closed;
  record.attempt = frame.estimate.attempt;
  record.odometry_scale = frame.estimate.odometry_scale;
  record.odometry_scale_sigma = frame.estimate.odometry_scale_sigma;
  record.odometry_scale_applied = frame.estimate.odometry_scale_applied;
  record.srel_percent = frame.estimate.registration.srel_percent;
  record.iterations = frame.estimate.registration.iterations;
  record.scan_points = static_cast<int>(frame.scan.points.size());
  record.stage_ms = frame.timings.stage_ms;
  record.wait_ms = frame.timings.wait_ms;
  record.queue_depth = frame.timings.queue_depth;
  record.latency_ms = frame.timings.latency_ms;
  record.dropped_before = static_cast<int>(frame.dropped_before);
  return record;
}

}  // namespace omnislam::app
