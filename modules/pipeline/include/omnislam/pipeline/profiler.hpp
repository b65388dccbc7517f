#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "omnislam/pipeline/frame.hpp"

/// @file
/// Rolling per-stage statistics of the last frames (architecture.md "Pipeline", profile).

namespace omnislam::pipeline {

/// Statistics of one series of durations, milliseconds.
struct DurationStats {
  std::uint64_t count = 0;
  double mean_ms = 0.0;
  double p50_ms = 0.0;
  double p99_ms = 0.0;
  double max_ms = 0.0;
  double share = 0.0;  ///< of the summed stage means (stages only; 0 for waits and latency)
};

/// count, mean, nearest-rank p50/p99 (index q * (n - 1) of the sorted values) and max.
/// Empty input gives all zeros.
[[nodiscard]] DurationStats summarize(std::vector<double> values_ms);

/// What rt/omnislam/profile and the end-of-run summary report.
struct ProfileSnapshot {
  std::uint64_t frames_captured = 0;
  std::uint64_t frames_dropped = 0;  ///< by capture in live mode
  std::uint64_t frames_out = 0;      ///< handed to the sinks
  std::array<DurationStats, kStages.size()> stages;
  std::array<DurationStats, kQueues.size()> waits;
  DurationStats latency;
  std::array<int, kQueues.size()> queue_depth_max{};  ///< over the window
  std::array<int, kQueues.size()> queue_capacity{};
};

/// Keeps the timings of the last `window` frames. Single-threaded: the publish stage owns it.
class Profiler {
 public:
  explicit Profiler(std::size_t window = 300) : window_(window == 0 ? 1 : window) {}

  void add(const FrameTimings &timings);

  /// Statistics of the frames in the window (counters left zero for the caller to fill).
  [[nodiscard]] ProfileSnapshot snapshot() const;

 private:
  std::size_t window_;
  std::vector<FrameTimings> ring_;
  std::size_t next_ = 0;
};

}  // namespace omnislam::pipeline
