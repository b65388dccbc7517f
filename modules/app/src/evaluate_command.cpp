#include "evaluate_command.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

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

nlohmann::json to_json(const slam::TrajectoryError &e) {
  return {{"rmse_m", e.rmse_m}, {"max_m", e.max_m}, {"final_m", e.final_m}, {"max_frame", e.max_frame + 1}};
}

void evaluate(const std::filesystem::path &run_dir, const std::filesystem::path &dataset_dir) {
  const io::DatasetInfo info = io::read_dataset_info(dataset_dir);
  if (info.groundtruth.empty())
    throw std::runtime_error(dataset_dir.string() + ": no groundtruth in dataset.yaml");
  auto truth = io::relative_to_first(io::to_isometries(io::read_tum_file(info.groundtruth)));
  auto odometry = io::relative_to_first(io::to_isometries(io::read_tum_file(info.odometry)));
  const auto estimate = io::to_isometries(io::read_tum_file(run_dir / "trajectory.tum"));
  if (estimate.size() > truth.size()) {
    throw std::runtime_error((run_dir / "trajectory.tum").string() + " has " +
                             std::to_string(estimate.size()) + " poses but the ground truth only " +
                             std::to_string(truth.size()));
  }
  truth.resize(estimate.size());
  odometry.resize(estimate.size());
  const auto slam_error = slam::trajectory_error(estimate, truth);
  const auto odometry_error = slam::trajectory_error(odometry, truth);

  slam::Points2 map_points;
  for (const io::MapPointRecord &p : io::read_map_csv(run_dir / "map.csv"))
    map_points.emplace_back(p.x_m, p.y_m);
  const auto map = slam::map_error(map_points, floorplan_segments(info.floorplan));

  std::printf("trajectory (%zu frames): rmse %.1f mm, max %.1f mm (frame %d), final %.1f mm\n",
              estimate.size(), slam_error.rmse_m * 1e3, slam_error.max_m * 1e3, slam_error.max_frame + 1,
              slam_error.final_m * 1e3);
  std::printf("odometry alone:          rmse %.1f mm, max %.1f mm (frame %d), final %.1f mm\n",
              odometry_error.rmse_m * 1e3, odometry_error.max_m * 1e3, odometry_error.max_frame + 1,
              odometry_error.final_m * 1e3);
  std::printf("map (%zu points): median distance to floor plan %.1f mm, p90 %.1f mm, completeness %.1f%%\n",
              map.points, map.median_distance_m * 1e3, map.p90_distance_m * 1e3, map.completeness * 100.0);

  nlohmann::json out;
  out["ate"] = to_json(slam_error);
  out["odometry_ate"] = to_json(odometry_error);
  out["map"] = {{"points", map.points},
                {"median_distance_m", map.median_distance_m},
                {"p90_distance_m", map.p90_distance_m},
                {"completeness", map.completeness}};
  io::write_text_file(run_dir / "evaluation.json", out.dump(2) + "\n");
  std::ostringstream csv;
  csv << "frame,error_m,odometry_error_m\n";
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    csv << i + 1 << ',' << slam_error.per_frame_m[i] << ',' << odometry_error.per_frame_m[i] << '\n';
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
