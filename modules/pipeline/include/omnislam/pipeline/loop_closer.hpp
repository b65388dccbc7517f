#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include "omnislam/slam/loop_job.hpp"

/// @file
/// The loop-closure worker beside the SLAM stage: one thread that runs slam::run_loop_job
/// on the jobs the SLAM stage hands it, in order, one at a time, and keeps the results
/// until the SLAM stage takes them between two frames.

namespace omnislam::pipeline {

/// Jobs and results pass under one mutex: a few per second, never inside a per-point loop.
/// The queues hold what slam::Slam hands out, at most one job and its result at a time
/// (Slam::take_loop_job gives no new job before the last result was applied). Non-copyable.
/// Thread-safety: submit, try_take and wait_take from one thread (the SLAM stage); the
/// destructor from that thread or after it ended.
class LoopCloser {
 public:
  /// Starts the worker thread at `nice` (Linux: a thread's own nice value, 0..19; higher
  /// yields more): the per-frame stages then keep the cores they share with it.
  explicit LoopCloser(int nice = 0);
  LoopCloser(const LoopCloser &) = delete;
  LoopCloser &operator=(const LoopCloser &) = delete;
  /// Lets the job in progress finish, drops jobs not started and results not taken, joins.
  ~LoopCloser();

  /// Queues a job for the worker; never blocks on the job.
  void submit(slam::LoopJob job);
  /// The oldest finished result, or nullopt at once when none is ready.
  [[nodiscard]] std::optional<slam::LoopResult> try_take();
  /// The oldest result, waiting for the job in progress or queued; nullopt when there is
  /// no job at all.
  [[nodiscard]] std::optional<slam::LoopResult> wait_take();
  /// Jobs finished so far (thread-safe).
  [[nodiscard]] std::uint64_t jobs_done() const;

 private:
  void run(int nice);

  mutable std::mutex mutex_;
  std::condition_variable job_ready_;     ///< the worker waits for a job or stop
  std::condition_variable result_ready_;  ///< wait_take waits for a result
  std::deque<slam::LoopJob> jobs_;
  std::deque<slam::LoopResult> results_;
  bool working_ = false;  ///< the worker runs a job taken off jobs_
  bool stop_ = false;
  std::uint64_t done_ = 0;
  std::thread thread_;  ///< last: starts once the members above exist
};

}  // namespace omnislam::pipeline
