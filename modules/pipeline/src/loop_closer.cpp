#include "omnislam/pipeline/loop_closer.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <utility>

namespace omnislam::pipeline {

LoopCloser::LoopCloser(int nice) : thread_([this, nice] { run(nice); }) {}

LoopCloser::~LoopCloser() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  job_ready_.notify_one();
  thread_.join();
}

void LoopCloser::submit(slam::LoopJob job) {
  {
    const std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(job));
  }
  job_ready_.notify_one();
}

std::optional<slam::LoopResult> LoopCloser::try_take() {
  const std::lock_guard lock(mutex_);
  if (results_.empty()) return std::nullopt;
  slam::LoopResult result = std::move(results_.front());
  results_.pop_front();
  return result;
}

std::optional<slam::LoopResult> LoopCloser::wait_take() {
  std::unique_lock lock(mutex_);
  result_ready_.wait(lock, [this] { return !results_.empty() || (jobs_.empty() && !working_); });
  if (results_.empty()) return std::nullopt;
  slam::LoopResult result = std::move(results_.front());
  results_.pop_front();
  return result;
}

std::uint64_t LoopCloser::jobs_done() const {
  const std::lock_guard lock(mutex_);
  return done_;
}

void LoopCloser::run(int nice) {
  // Linux gives each thread its own nice value. Failing to lower the priority only costs
  // latency, so the result is not checked.
  if (nice > 0) (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice);
  for (;;) {
    std::optional<slam::LoopJob> job;
    {
      std::unique_lock lock(mutex_);
      job_ready_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
      if (stop_) return;
      job = std::move(jobs_.front());
      jobs_.pop_front();
      working_ = true;
    }
    // The search, solve and rebuild run unlocked: the SLAM stage goes on meanwhile.
    slam::LoopResult result = slam::run_loop_job(std::move(*job));
    {
      const std::lock_guard lock(mutex_);
      results_.push_back(std::move(result));
      working_ = false;
      ++done_;
    }
    result_ready_.notify_one();
  }
}

}  // namespace omnislam::pipeline
