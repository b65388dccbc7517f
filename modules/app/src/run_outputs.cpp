#include "run_outputs.hpp"
#include "omnislam/slam/planar_pose.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "omnislam/io/poses.hpp"
#include "omnislam/io/run_files.hpp"
#include "omnislam/pipeline/profiler.hpp"
#include "omnislam/slam/evaluation.hpp"

namespace omnislam::app {
namespace {

constexpr double kMmPerM = 1000.0;
constexpr double kDegPerRad = 180.0 / std::numbers::pi;

nlohmann::json stage_statistics(const std::vector<FrameRecord> &frames) {
  nlohmann::json stages = nlohmann::json::object();
  for (std::size_t s = 0; s < kStages.size(); ++s) {
    std::vector<double> ms;
    for (const FrameRecord &f : frames) ms.push_back(f.stage_ms[s]);
    std::sort(ms.begin(), ms.end());
    double mean = 0.0;
    for (double v : ms) mean += v;
    mean = ms.empty() ? 0.0 : mean / static_cast<double>(ms.size());
    auto at = [&](double q) { return ms.empty() ? 0.0 : ms[static_cast<std::size_t>(q * (ms.size() - 1))]; };
    stages[std::string(kStages[s])] = {{"mean", mean}, {"p50", at(0.5)}, {"p99", at(0.99)}};
  }
  return stages;
}

nlohmann::json errors_json(const slam::TrajectoryError &e) {
  return {{"rmse_m", e.rmse_m}, {"max_m", e.max_m}, {"final_m", e.final_m}, {"max_frame", e.max_frame + 1}};
}

std::string thesis_localisation(const RunRecord &run) {
  std::ostringstream out;
  char line[128];
  for (const FrameRecord &f : run.frames) {
    if (f.integrated) {
      std::snprintf(line, sizeof line, "%.3f %.3f %.4f\n", f.T_map_base.translation().x() * kMmPerM,
                    f.T_map_base.translation().y() * kMmPerM, slam::yaw_rad_of(f.T_map_base) * kDegPerRad);
    } else {
      std::snprintf(line, sizeof line, "0 0 0\n");
    }
    out << line;
  }
  return out.str();
}

std::string thesis_vectors(const RunRecord &run) {
  std::ostringstream out;
  out << "# image attempt srel_percent mean_srel_percent iterations\n";
  double srel_sum = 0.0;
  int accepted = 0;
  char line[128];
  for (std::size_t i = 0; i < run.frames.size(); ++i) {
    const FrameRecord &f = run.frames[i];
    if (f.integrated) {
      srel_sum += f.srel_percent;
      ++accepted;
    }
    std::snprintf(line, sizeof line, "%zu %d %.3f %.3f %d\n", i + 1, static_cast<int>(f.attempt),
                  f.srel_percent, accepted ? srel_sum / accepted : 0.0, f.iterations);
    out << line;
  }
  return out.str();
}

std::string thesis_odometry(const RunRecord &run) {
  std::ostringstream out;
  char line[96];
  for (const Eigen::Isometry2d &T : run.odometry_map) {
    std::snprintf(line, sizeof line, "%.3f %.3f\n", T.translation().x() * kMmPerM,
                  T.translation().y() * kMmPerM);
    out << line;
  }
  return out.str();
}

std::string profile_csv(const RunRecord &run, bool thesis_timelog) {
  std::ostringstream out;
  out << (thesis_timelog ? "# image" : "frame");
  for (std::string_view stage : kStages)
    out << (thesis_timelog ? " " : ",") << stage << (thesis_timelog ? "" : "_ms");
  // profile.csv goes on with the pipeline's queues (the thesis's timelog stops at the stages).
  if (!thesis_timelog) {
    for (std::string_view queue : kQueues) out << ",wait_" << queue << "_ms";
    for (std::string_view queue : kQueues) out << ",depth_" << queue;
    out << ",latency_ms,dropped_before";
  }
  out << '\n';
  char value[32];
  for (std::size_t i = 0; i < run.frames.size(); ++i) {
    const FrameRecord &f = run.frames[i];
    out << i + 1;
    for (double ms : f.stage_ms) {
      std::snprintf(value, sizeof value, "%s%.4f", thesis_timelog ? " " : ",", ms);
      out << value;
    }
    if (!thesis_timelog) {
      for (double ms : f.wait_ms) {
        std::snprintf(value, sizeof value, ",%.4f", ms);
        out << value;
      }
      for (int depth : f.queue_depth) out << ',' << depth;
      std::snprintf(value, sizeof value, ",%.4f,%d", f.latency_ms, f.dropped_before);
      out << value;
    }
    out << '\n';
  }
  return out.str();
}

std::vector<io::CovarianceRecord> covariance_records(const RunRecord &run) {
  std::vector<io::CovarianceRecord> rows;
  for (std::size_t i = 0; i < run.frames.size(); ++i)
    rows.push_back({static_cast<int>(i) + 1, run.frames[i].t_s, run.frames[i].covariance});
  return rows;
}

std::vector<io::MapPointRecord> map_records(const slam::PointMap &map) {
  std::vector<io::MapPointRecord> records;
  records.reserve(map.points().size());
  for (const slam::MapPoint &p : map.points())
    records.push_back({p.position_m.x(), p.position_m.y(), p.hits});
  return records;
}

// The frames that have a pose, with their ground truth and odometry.
RunRecord with_pose(const RunRecord &run) {
  RunRecord posed = run;
  posed.frames.clear();
  posed.ground_truth.clear();
  posed.odometry_map.clear();
  for (std::size_t i = 0; i < run.frames.size(); ++i) {
    if (!run.frames[i].localized) continue;
    posed.frames.push_back(run.frames[i]);
    if (i < run.ground_truth.size()) posed.ground_truth.push_back(run.ground_truth[i]);
    if (i < run.odometry_map.size()) posed.odometry_map.push_back(run.odometry_map[i]);
  }
  return posed;
}

}  // namespace

OutputWriter::OutputWriter(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code error;
  std::filesystem::create_directories(dir_, error);
  if (error) throw std::runtime_error("cannot create " + dir_.string() + ": " + error.message());
}

void OutputWriter::write_thesis_map(int frame, const std::vector<slam::MapPoint> &points) const {
  std::ostringstream out;
  char line[96];
  for (const slam::MapPoint &p : points) {
    std::snprintf(line, sizeof line, "%.3f %.3f %d\n", p.position_m.x() * kMmPerM, p.position_m.y() * kMmPerM,
                  p.hits);
    out << line;
  }
  io::write_text_file(dir_ / ("mapa" + std::to_string(frame) + ".txt"), out.str());
}

void OutputWriter::write_all(const RunRecord &all, const slam::PointMap &map, const io::DatasetInfo &info,
                             const std::vector<Eigen::Isometry2d> &optimised) const {
  // Frames still searching for their pose on a saved map have none: the pose files, the
  // covariance and the errors are of the frames that have one (all of them, unless localizing).
  // A lost frame has its dead-reckoned pose online; in the final trajectory too unless the
  // robot was found again, which placed it back by odometry (summary: lost).
  const RunRecord run = with_pose(all);
  std::vector<io::StampedPose> trajectory, trajectory_online;
  std::vector<Eigen::Isometry2d> online;
  for (const FrameRecord &f : run.frames) {
    trajectory_online.push_back(io::to_stamped(f.t_s, f.T_map_base));
    online.push_back(f.T_map_base);
  }
  const std::vector<Eigen::Isometry2d> estimate = optimised.size() == run.frames.size() ? optimised : online;
  for (std::size_t i = 0; i < run.frames.size(); ++i)
    trajectory.push_back(io::to_stamped(run.frames[i].t_s, estimate[i]));
  io::write_tum_file(dir_ / "trajectory.tum", trajectory);
  io::write_tum_file(dir_ / "trajectory_online.tum", trajectory_online);
  const auto records = map_records(map);
  io::write_map_csv(dir_ / "map.csv", records);
  io::write_map_ply(dir_ / "map.ply", records);
  io::write_text_file(dir_ / "profile.csv", profile_csv(all, false));
  io::write_covariance_csv(dir_ / "covariance.csv", covariance_records(run));
  io::write_text_file(dir_ / "timelog.txt", profile_csv(all, true));
  io::write_text_file(dir_ / "autolocalizacao.txt", thesis_localisation(run));
  io::write_text_file(dir_ / "vetores.txt", thesis_vectors(run));
  io::write_text_file(dir_ / "odometriaxy.txt", thesis_odometry(run));

  nlohmann::json summary;
  summary["dataset"] = info.name;
  summary["frames"] = all.frames.size();
  const auto integrated =
      std::count_if(all.frames.begin(), all.frames.end(), [](auto &f) { return f.integrated; });
  summary["integrated"] = integrated;
  summary["not_integrated"] = static_cast<long>(all.frames.size()) - integrated;
  summary["skipped"] = std::count_if(all.frames.begin(), all.frames.end(), [](auto &f) { return f.skipped; });
  if (all.localizing) summary["not_localized"] = all.frames.size() - run.frames.size();
  summary["lost"] = std::count_if(all.frames.begin(), all.frames.end(), [](auto &f) { return f.lost; });
  // Each stretch of lost frames as [first, last] (1-based frame numbers).
  nlohmann::json spans = nlohmann::json::array();
  for (std::size_t i = 0; i < all.frames.size(); ++i) {
    if (!all.frames[i].lost) continue;
    if (i > 0 && all.frames[i - 1].lost) {
      spans.back()[1] = i + 1;
    } else {
      spans.push_back({i + 1, i + 1});
    }
  }
  summary["lost_spans"] = spans;
  // The frames a pose was confirmed at by the search of the map (1-based).
  nlohmann::json relocalized = nlohmann::json::array();
  for (std::size_t i = 0; i < all.frames.size(); ++i)
    if (all.frames[i].relocalized) relocalized.push_back(i + 1);
  summary["relocalized"] = relocalized.size();
  summary["relocalized_frames"] = relocalized;
  summary["keyframes"] =
      std::count_if(run.frames.begin(), run.frames.end(), [](auto &f) { return f.keyframe; });
  summary["revisits"] =
      std::count_if(run.frames.begin(), run.frames.end(), [](auto &f) { return f.revisit; });
  summary["mapped"] = std::count_if(run.frames.begin(), run.frames.end(), [](auto &f) { return f.mapped; });
  summary["loop_closures"] =
      std::count_if(run.frames.begin(), run.frames.end(), [](auto &f) { return f.loop_closed; });
  summary["map_points"] = map.points().size();
  if (!run.frames.empty()) {
    // How far the odometry reads long or short, as the scans measured it by the last frame.
    const FrameRecord &last = run.frames.back();
    summary["odometry_scale"] = {{"factor", last.odometry_scale},
                                 {"sigma", last.odometry_scale_sigma},
                                 {"applied", last.odometry_scale_applied}};
  }
  summary["stage_ms"] = stage_statistics(run.frames);
  std::vector<double> latency_ms;
  long dropped = 0;
  for (const FrameRecord &f : all.frames) {
    latency_ms.push_back(f.latency_ms);
    dropped += f.dropped_before;
  }
  const pipeline::DurationStats latency = pipeline::summarize(latency_ms);
  summary["latency_ms"] = {{"mean", latency.mean_ms}, {"p50", latency.p50_ms}, {"p99", latency.p99_ms}};
  summary["dropped"] = dropped;
  if (run.degradation_factors != "none") {
    summary["degradation"] = {{"factors", run.degradation_factors}, {"seed", run.degradation_seed}};
  }
  if (run.ground_truth.size() == estimate.size() && !estimate.empty()) {
    const auto slam_error = slam::trajectory_error(estimate, run.ground_truth);
    const auto odometry_error = slam::trajectory_error(run.odometry_map, run.ground_truth);
    summary["ate"] = errors_json(slam_error);
    summary["online_ate"] = errors_json(slam::trajectory_error(online, run.ground_truth));
    summary["odometry_ate"] = errors_json(odometry_error);
    std::printf(
        "%s: %zu frames, %ld integrated; position error max %.1f mm, final %.1f mm, rmse %.1f mm "
        "(odometry alone: max %.1f mm)\n",
        info.name.c_str(), run.frames.size(), static_cast<long>(integrated), slam_error.max_m * kMmPerM,
        slam_error.final_m * kMmPerM, slam_error.rmse_m * kMmPerM, odometry_error.max_m * kMmPerM);
  }
  io::write_text_file(dir_ / "summary.json", summary.dump(2) + "\n");
}

}  // namespace omnislam::app
