#pragma once

#include <atomic>
#include <csignal>
#include <cstdint>

#include "omnislam/io/snapshot.hpp"
#include "omnislam/pipeline/pipeline.hpp"
#include "systemd_notify.hpp"

// omnislamd's main thread while the pipeline runs: signals, the systemd watchdog, STATUS.
namespace omnislam::app {

/// Counts of the frames that reached the sinks, continued from a resumed snapshot.
/// `totals` and `in_odometry_gap` belong to the publish thread; the atomics are also read by
/// the main thread for STATUS.
struct FrameCounts {
  io::SnapshotCounters totals;
  std::atomic<std::uint64_t> skipped{0};
  std::atomic<std::uint64_t> without_odometry{0};
  std::atomic<std::size_t> map_points{0};  ///< of the last map attached to a frame
  bool in_odometry_gap = false;
};

/// Waits for SIGINT/SIGTERM (blocked in every thread, taken here) or the end of the input.
/// Meanwhile pets the watchdog while no stage has been busy with one frame for more than
/// `stage_timeout_s`, logs a hung stage by name, and sends STATUS every second. Returns
/// true on a signal, false when the input ended.
bool supervise(const pipeline::Pipeline &pipeline, const sigset_t &signals, const SystemdNotifier &notifier,
               double stage_timeout_s, const FrameCounts &counts);

}  // namespace omnislam::app
