#include "evaluate_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/io/run_files.hpp"
#include "omnislam/slam/evaluation.hpp"

namespace omnislam::app {
namespace {

std::vector<slam::Segment2> floorplan_segments(const std::filesystem::path &file) {
  std::vector<slam::Segment2> segments;
  for (const io::FloorplanSegment &s : io::read_floorplan_csv(file)) {
    segments.push_back({{s.x1_m, s.y1_m}, {s.x2_m, s.y2_m}});
  }
  return segments;
}

// max_frame: the 1-based dataset frame of the largest error.
nlohmann::json to_json(const slam::TrajectoryError &e, int max_frame) {
  return {{"rmse_m", e.rmse_m}, {"max_m", e.max_m}, {"final_m", e.final_m}, {"max_frame", max_frame}};
}

void evaluate(const std::filesystem::path &run_dir, const std::filesystem::path &dataset_dir) {
  const io::DatasetInfo info = io::read_dataset_info(dataset_dir);
  if (info.groundtruth.empty())
    throw std::runtime_error(dataset_dir.string() + ": no groundtruth in dataset.yaml");
  const auto all_truth = io::relative_to_first(io::to_isometries(io::read_tum_file(info.groundtruth)));
  const auto all_odometry = io::relative_to_first(io::to_isometries(io::read_tum_file(info.odometry)));
  const auto stamped = io::read_tum_file(run_dir / "trajectory.tum");
  // Each pose is compared with the ground truth of its dataset frame, found from its time
  // stamp ((frame - 1) / rate): a resumed run starts later, a looped one plays frames again.
  std::vector<Eigen::Isometry2d> estimate, truth, odometry;
  std::vector<int> frame_of;  // 0-based dataset frame of each pose
  const std::size_t frames = std::min(all_truth.size(), all_odometry.size());
  for (std::size_t i = 0; i < stamped.size(); ++i) {
    const double index = stamped[i].t_s * info.rate_hz;
    const double rounded = std::round(index);
    if (std::abs(index - rounded) > 1e-3 || rounded < 0.0 || frames == 0) {
      throw std::runtime_error((run_dir / "trajectory.tum").string() + ": pose " + std::to_string(i + 1) +
                               " at t " + std::to_string(stamped[i].t_s) + " s is not at a frame time of " +
                               dataset_dir.string() + " (" + std::to_string(info.rate_hz) + " Hz)");
    }
    const auto frame = static_cast<std::size_t>(rounded) % frames;
    estimate.push_back(io::to_isometry(stamped[i]));
    truth.push_back(all_truth[frame]);
    odometry.push_back(all_odometry[frame]);
    frame_of.push_back(static_cast<int>(frame));
  }
  if (estimate.empty()) throw std::runtime_error((run_dir / "trajectory.tum").string() + ": no poses");
  // The poses as they were published (a run with a pose graph; older runs have only
  // trajectory.tum, which then is the online trajectory too): same frames, same order.
  std::vector<Eigen::Isometry2d> online = estimate;
  const bool has_online = std::filesystem::exists(run_dir / "trajectory_online.tum");
  if (has_online) {
    online = io::to_isometries(io::read_tum_file(run_dir / "trajectory_online.tum"));
    if (online.size() != estimate.size()) {
      throw std::runtime_error((run_dir / "trajectory_online.tum").string() + ": " +
                               std::to_string(online.size()) + " poses for " +
                               std::to_string(estimate.size()) + " in trajectory.tum");
    }
  }
  const auto slam_error = slam::trajectory_error(estimate, truth);
  const auto odometry_error = slam::trajectory_error(odometry, truth);
  const auto online_error = slam::trajectory_error(online, truth);

  slam::Points2 map_points;
  for (const io::MapPointRecord &p : io::read_map_csv(run_dir / "map.csv"))
    map_points.emplace_back(p.x_m, p.y_m);
  const auto map = slam::map_error(map_points, floorplan_segments(info.floorplan));

  std::printf("trajectory (%zu frames): rmse %.1f mm, max %.1f mm (frame %d), final %.1f mm\n",
              estimate.size(), slam_error.rmse_m * 1e3, slam_error.max_m * 1e3,
              frame_of[slam_error.max_frame] + 1, slam_error.final_m * 1e3);
  if (has_online) {
    std::printf("online (as published):   rmse %.1f mm, max %.1f mm (frame %d), final %.1f mm\n",
                online_error.rmse_m * 1e3, online_error.max_m * 1e3, frame_of[online_error.max_frame] + 1,
                online_error.final_m * 1e3);
  }
  std::printf("odometry alone:          rmse %.1f mm, max %.1f mm (frame %d), final %.1f mm\n",
              odometry_error.rmse_m * 1e3, odometry_error.max_m * 1e3, frame_of[odometry_error.max_frame] + 1,
              odometry_error.final_m * 1e3);
  std::printf("map (%zu points): median distance to floor plan %.1f mm, p90 %.1f mm, completeness %.1f%%\n",
              map.points, map.median_distance_m * 1e3, map.p90_distance_m * 1e3, map.completeness * 100.0);

  // The covariance (of the online poses) against their errors, when the run wrote one per pose.
  std::optional<slam::CovarianceConsistency> consistency;
  if (std::filesystem::exists(run_dir / "covariance.csv")) {
    const auto rows = io::read_covariance_csv(run_dir / "covariance.csv");
    if (rows.size() != estimate.size()) {
      throw std::runtime_error((run_dir / "covariance.csv").string() + ": " + std::to_string(rows.size()) +
                               " rows for " + std::to_string(estimate.size()) + " poses in the trajectory");
    }
    std::vector<Eigen::Matrix3d> covariances;
    for (const io::CovarianceRecord &row : rows) covariances.push_back(row.covariance);
    consistency = slam::covariance_consistency(online, truth, covariances);
    std::printf(
        "covariance (%d frames): mean NEES %.1f (consistent: ~3), %.1f%% of positions inside their 95%% "
        "ellipse\n",
        consistency->frames, consistency->mean_nees, consistency->inside_95_share * 100.0);
  }

  nlohmann::json out;
  out["ate"] = to_json(slam_error, frame_of[slam_error.max_frame] + 1);
  if (has_online) out["online_ate"] = to_json(online_error, frame_of[online_error.max_frame] + 1);
  if (consistency) {
    out["covariance"] = {{"frames", consistency->frames},
                         {"mean_nees", consistency->mean_nees},
                         {"inside_95_share", consistency->inside_95_share}};
  }
  out["odometry_ate"] = to_json(odometry_error, frame_of[odometry_error.max_frame] + 1);
  out["map"] = {{"points", map.points},
                {"median_distance_m", map.median_distance_m},
                {"p90_distance_m", map.p90_distance_m},
                {"completeness", map.completeness}};
  io::write_text_file(run_dir / "evaluation.json", out.dump(2) + "\n");
  std::ostringstream csv;
  csv << "frame,error_m,odometry_error_m\n";
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    csv << frame_of[i] + 1 << ',' << slam_error.per_frame_m[i] << ',' << odometry_error.per_frame_m[i]
        << '\n';
  }
  io::write_text_file(run_dir / "errors.csv", csv.str());
}

}  // namespace

void add_evaluate_command(CLI::App &app) {
  auto *command = app.add_subcommand("evaluate", "trajectory and map error of a run against ground truth");
  auto run_dir = std::make_shared<std::string>();
  auto dataset = std::make_shared<std::string>();
  command->add_option("run", *run_dir, "output directory of omnislam replay")->required();
  command->add_option("dataset", *dataset, "dataset directory")->required();
  command->callback([run_dir, dataset] { evaluate(*run_dir, *dataset); });
}

}  // namespace omnislam::app
