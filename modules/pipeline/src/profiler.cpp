#include "omnislam/pipeline/profiler.hpp"

#include <algorithm>
#include <numeric>

namespace omnislam::pipeline {

DurationStats summarize(std::vector<double> values_ms) {
  DurationStats stats;
  if (values_ms.empty()) return stats;
  std::sort(values_ms.begin(), values_ms.end());
  const auto at = [&](double q) {
    return values_ms[static_cast<std::size_t>(q * static_cast<double>(values_ms.size() - 1))];
  };
  stats.count = values_ms.size();
  stats.mean_ms = std::accumulate(values_ms.begin(), values_ms.end(), 0.0) / static_cast<double>(stats.count);
  stats.p50_ms = at(0.5);
  stats.p99_ms = at(0.99);
  stats.max_ms = values_ms.back();
  return stats;
}

void Profiler::add(const FrameTimings &timings) {
  if (ring_.size() < window_) {
    ring_.push_back(timings);
  } else {
    ring_[next_] = timings;
  }
  next_ = (next_ + 1) % window_;
}

ProfileSnapshot Profiler::snapshot() const {
  ProfileSnapshot snapshot;
  std::vector<double> values;
  values.reserve(ring_.size());
  const auto series = [&](auto &&pick) {
    values.clear();
    for (const FrameTimings &t : ring_) values.push_back(pick(t));
    return summarize(values);
  };
  double total_ms = 0.0;
  for (std::size_t s = 0; s < kStages.size(); ++s) {
    snapshot.stages[s] = series([s](const FrameTimings &t) { return t.stage_ms[s]; });
    total_ms += snapshot.stages[s].mean_ms;
  }
  for (DurationStats &stage : snapshot.stages) stage.share = total_ms > 0.0 ? stage.mean_ms / total_ms : 0.0;
  for (std::size_t q = 0; q < kQueues.size(); ++q) {
    snapshot.waits[q] = series([q](const FrameTimings &t) { return t.wait_ms[q]; });
    for (const FrameTimings &t : ring_)
      snapshot.queue_depth_max[q] = std::max(snapshot.queue_depth_max[q], t.queue_depth[q]);
  }
  snapshot.latency = series([](const FrameTimings &t) { return t.latency_ms; });
  return snapshot;
}

}  // namespace omnislam::pipeline
