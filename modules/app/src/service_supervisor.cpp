#include "service_supervisor.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <optional>
#include <string>

namespace omnislam::app {

bool supervise(const pipeline::Pipeline &pipeline, const sigset_t &signals, const SystemdNotifier &notifier,
               double stage_timeout_s, const FrameCounts &counts) {
  const timespec tick{0, 100'000'000};
  const auto stage_timeout =
      std::chrono::duration_cast<pipeline::Clock::duration>(std::chrono::duration<double>(stage_timeout_s));
  const auto pet_every = notifier.watchdog_interval() / 2;
  auto last_status = std::chrono::steady_clock::now();
  auto last_pet = last_status - pet_every;  // pet at once
  std::optional<std::size_t> hung;
  while (!pipeline.finished()) {
    const auto now = std::chrono::steady_clock::now();
    const std::optional<std::size_t> stuck = pipeline.stuck_stage(stage_timeout);
    if (stuck && !hung) {
      spdlog::error("the {} stage has been busy with one frame for more than {} s: it hangs{}",
                    pipeline::Pipeline::kThreads[*stuck], stage_timeout_s,
                    notifier.watchdog_enabled() ? "; the systemd watchdog is no longer petted" : "");
      notifier.status(std::string("hung in the ") + std::string(pipeline::Pipeline::kThreads[*stuck]) +
                      " stage");
    } else if (!stuck && hung) {
      spdlog::warn("the {} stage moves again", pipeline::Pipeline::kThreads[*hung]);
    }
    hung = stuck;
    if (!hung && notifier.watchdog_enabled() && now - last_pet >= pet_every) {
      notifier.watchdog();
      last_pet = now;
    }
    if (!hung && now - last_status >= std::chrono::seconds(1)) {
      notifier.status("running: frames in " + std::to_string(pipeline.frames_captured()) + ", out " +
                      std::to_string(pipeline.frames_out()) + ", dropped " +
                      std::to_string(pipeline.frames_dropped()) + ", skipped " +
                      std::to_string(counts.skipped.load(std::memory_order_relaxed)) + ", without odometry " +
                      std::to_string(counts.without_odometry.load(std::memory_order_relaxed)) + "; map " +
                      std::to_string(counts.map_points.load(std::memory_order_relaxed)) + " points");
      last_status = now;
    }
    const int signal = sigtimedwait(&signals, nullptr, &tick);
    if (signal > 0) {
      spdlog::info("signal {}: draining the pipeline", signal);
      return true;
    }
  }
  return false;
}

}  // namespace omnislam::app
