#include "map_command.hpp"
#include "omnislam/slam/planar_pose.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "omnislam/grid/occupancy_grid.hpp"
#include "omnislam/io/grid_files.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/io/run_files.hpp"
#include "omnislam/io/snapshot.hpp"

namespace omnislam::app {
namespace {

// How far the map may be off by place (its keyframes' covariances, version 6): the spread of
// their position and heading standard deviations (the position's along its worst direction).
void print_map_uncertainty(const slam::KeyframeGraphState &graph, std::uint32_t version) {
  if (version < 6 || graph.keyframes.empty()) {
    std::printf("map uncertainty: unknown (snapshot version %u keeps no keyframe covariances)\n", version);
    return;
  }
  std::vector<double> position_mm, heading_deg;
  for (const slam::KeyframeGraphState::SavedKeyframe &keyframe : graph.keyframes) {
    const Eigen::Matrix2d position = keyframe.covariance.topLeftCorner<2, 2>();
    const double worst = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(position).eigenvalues().maxCoeff();
    position_mm.push_back(1000.0 * std::sqrt(std::max(0.0, worst)));
    heading_deg.push_back(std::sqrt(std::max(0.0, keyframe.covariance(2, 2))) * 180.0 / std::numbers::pi);
  }
  const auto spread = [](std::vector<double> &values) {
    std::sort(values.begin(), values.end());
    return std::array<double, 3>{values.front(), values[values.size() / 2], values.back()};
  };
  const auto [p_min, p_median, p_max] = spread(position_mm);
  const auto [h_min, h_median, h_max] = spread(heading_deg);
  std::printf(
      "map uncertainty (keyframes, 1 sigma, min / median / max): position %.1f / %.1f / %.1f mm, "
      "heading %.3f / %.3f / %.3f deg\n",
      p_min, p_median, p_max, h_min, h_median, h_max);
}

void print_info(const std::filesystem::path &file) {
  const io::Snapshot s = io::read_snapshot(file);
  const double yaw_deg = slam::yaw_rad_of(s.T_map_base) * 180.0 / std::numbers::pi;
  const io::SnapshotCounters &n = s.counters;
  std::printf("snapshot: %s\n", file.c_str());
  std::printf("version: %u\n", s.version);
  std::printf("config_hash: %016" PRIx64 "\n", s.config_hash);
  std::printf("map points: %zu (after %d integrations)\n", s.points.size(), s.map_integrations);
  std::printf("pose: x %.4f m, y %.4f m, yaw %.3f deg, t %.3f s\n", s.T_map_base.translation().x(),
              s.T_map_base.translation().y(), yaw_deg, s.t_s);
  std::printf("pose sigma: x %.4f m, y %.4f m, yaw %.3f deg\n", std::sqrt(s.covariance(0, 0)),
              std::sqrt(s.covariance(1, 1)), std::sqrt(s.covariance(2, 2)) * 180.0 / std::numbers::pi);
  if (s.T_odom_base) {
    std::printf("odometry: x %.4f m, y %.4f m, yaw %.3f deg\n", s.T_odom_base->translation().x(),
                s.T_odom_base->translation().y(),
                slam::yaw_rad_of(*s.T_odom_base) * 180.0 / std::numbers::pi);
  } else {
    std::printf("odometry: none\n");
  }
  std::printf("frames: %" PRIu64 ", integrated %" PRIu64 ", not integrated %" PRIu64 ", skipped %" PRIu64
              ", dropped %" PRIu64 "\n",
              n.frames, n.integrated, n.not_integrated, n.skipped, n.dropped);
  if (s.grid) {
    std::printf(
        "occupancy grid: %d x %d cells at %.3f m, origin (%.3f, %.3f) m, %zu seen above the floor\n",
        s.grid->width, s.grid->height, s.grid->resolution_m, s.grid->origin_m.x(), s.grid->origin_m.y(),
        static_cast<std::size_t>(std::count(s.grid->above_floor.begin(), s.grid->above_floor.end(), 1)));
  } else {
    std::printf("occupancy grid: none\n");
  }
  if (s.graph) {
    const auto loops =
        std::count_if(s.graph->edges.begin(), s.graph->edges.end(),
                      [](const slam::KeyframeGraphState::SavedEdge &edge) { return edge.loop; });
    std::printf("keyframe graph: %zu keyframes, %zu edges (%td loop), %zu integrated scans, path %.2f m\n",
                s.graph->keyframes.size(), s.graph->edges.size(), loops, s.graph->integrations(),
                s.graph->path_m);
    print_map_uncertainty(*s.graph, s.version);
  } else {
    std::printf("keyframe graph: none\n");
  }
  if (s.odometry_scale) {
    std::printf(
        "odometry distance factor: %.4f +- %.4f (learnt; a run resumed or localized on it starts from it)\n",
        s.odometry_scale->factor, s.odometry_scale->sigma);
  } else {
    std::printf("odometry distance factor: none%s\n", s.version < 7 ? " (snapshot version < 7)" : "");
  }
}

// The last row of covariance.csv ("frame,t,xx,xy,yy,xyaw,yyaw,yawyaw"), or zero.
Eigen::Matrix3d last_covariance(const std::filesystem::path &file) {
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  double t = 0.0, xx = 0.0, xy = 0.0, yy = 0.0, xyaw = 0.0, yyaw = 0.0, yawyaw = 0.0;
  long frame = 0;
  if (std::sscanf(last.c_str(), "%ld,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &frame, &t, &xx, &xy, &yy, &xyaw, &yyaw,
                  &yawyaw) == 8) {
    c << xx, xy, xyaw, xy, yy, yyaw, xyaw, yyaw, yawyaw;
  }
  return c;
}

// A snapshot of a replay's output: map.csv, the last pose of trajectory.tum, and (when
// present) the last covariance and summary.json's counters.
void save(const std::filesystem::path &run_dir, const std::filesystem::path &file,
          const std::filesystem::path &config_file) {
  io::Snapshot s;
  s.config_hash = io::config_file_hash(config_file);
  const auto trajectory = io::read_tum_file(run_dir / "trajectory.tum");
  if (trajectory.empty()) throw std::runtime_error((run_dir / "trajectory.tum").string() + ": no poses");
  s.t_s = trajectory.back().t_s;
  s.T_map_base = io::to_isometry(trajectory.back());
  s.covariance = last_covariance(run_dir / "covariance.csv");
  s.counters.frames = trajectory.size();
  if (std::ifstream summary_file{run_dir / "summary.json"}) {
    const auto summary = nlohmann::json::parse(summary_file, nullptr, false);
    const auto count = [&](const char *key) { return summary.value(key, std::uint64_t{0}); };
    if (!summary.is_discarded() && summary.is_object()) {
      s.counters = {count("frames"), count("integrated"), count("not_integrated"), count("skipped"),
                    count("dropped")};
    }
  }
  s.map_integrations = static_cast<int>(s.counters.integrated);
  if (std::filesystem::exists(run_dir / "map.snapshot")) {
    // The same map with its keyframe graph (replays write it): a run localized on it later
    // knows how far the map may be off by place (the keyframes' covariances).
    io::Snapshot with_graph = io::read_snapshot(run_dir / "map.snapshot");
    s.map_integrations = with_graph.map_integrations;
    s.points = std::move(with_graph.points);
    s.graph = std::move(with_graph.graph);
    s.odometry_scale = with_graph.odometry_scale;
  } else {
    for (const io::MapPointRecord &p : io::read_map_csv(run_dir / "map.csv")) {
      s.points.push_back({{p.x_m, p.y_m}, p.hits, 0});
    }
  }
  if (std::filesystem::exists(run_dir / "map.yaml")) s.grid = io::read_nav2_map(run_dir / "map.yaml");
  io::write_snapshot(file, s);
  std::printf("saved %zu map points%s%s and the pose of frame %zu to %s\n", s.points.size(),
              s.grid ? ", the occupancy grid" : "", s.graph ? ", the keyframe graph" : "", trajectory.size(),
              file.c_str());
}

void load(const std::filesystem::path &file, const std::filesystem::path &out_dir) {
  const io::Snapshot s = io::read_snapshot(file);
  std::filesystem::create_directories(out_dir);
  std::vector<io::MapPointRecord> records;
  records.reserve(s.points.size());
  for (const slam::MapPoint &p : s.points) records.push_back({p.position_m.x(), p.position_m.y(), p.hits});
  io::write_map_csv(out_dir / "map.csv", records);
  io::write_map_ply(out_dir / "map.ply", records);
  io::write_tum_file(out_dir / "pose.tum", {io::to_stamped(s.t_s, s.T_map_base)});
  std::printf("wrote %zu map points to %s (map.csv, map.ply) and the pose to pose.tum\n", records.size(),
              out_dir.c_str());
}

// The grid of a snapshot without one (versions 1 and 2, or a writer that had none): each
// map point's cell occupied, everything else unknown; no free space is invented.
grid::GridImage grid_of_hits(const std::vector<slam::MapPoint> &points, double resolution_m) {
  grid::GridConfig config;
  config.resolution_m = resolution_m;
  grid::OccupancyGrid occupancy(config);
  std::vector<grid::Ray> rays;
  rays.reserve(points.size());
  for (const slam::MapPoint &p : points) {
    rays.push_back({std::atan2(p.position_m.y(), p.position_m.x()), p.position_m.norm(),
                    std::numeric_limits<double>::quiet_NaN()});
  }
  occupancy.add_scan(Eigen::Isometry2d::Identity(), rays);
  return occupancy.image();
}

// map.yaml + map.pgm from a snapshot (its grid, or its points when it has none) or from a
// replay's output directory (its map.yaml, read by nav2_map_server's trinary rules).
void export_map(const std::filesystem::path &source, const std::filesystem::path &out_dir,
                double resolution_m) {
  if (!std::filesystem::exists(source))
    throw std::runtime_error(source.string() + ": no such file or directory");
  grid::GridImage image;
  if (std::filesystem::is_directory(source)) {
    const std::filesystem::path yaml = source / "map.yaml";
    if (!std::filesystem::exists(yaml)) {
      throw std::runtime_error(source.string() +
                               ": no map.yaml (not an omnislam replay or omnislamd output directory)");
    }
    image = io::read_nav2_map(yaml);
  } else {
    const io::Snapshot s = io::read_snapshot(source);
    if (s.grid) {
      image = *s.grid;
    } else {
      std::fprintf(stderr,
                   "note: %s (snapshot version %u) holds no occupancy grid: exporting its %zu map points as "
                   "occupied cells at %.3f m; free space is unknown\n",
                   source.c_str(), s.version, s.points.size(), resolution_m);
      image = grid_of_hits(s.points, resolution_m);
    }
  }
  if (image.width <= 0) throw std::runtime_error(source.string() + ": the map is empty");
  std::filesystem::create_directories(out_dir);
  io::write_nav2_map(out_dir / "map.yaml", image);
  std::printf("wrote a %d x %d grid at %g m to %s (map.yaml, map.pgm)\n", image.width, image.height,
              image.resolution_m, out_dir.c_str());
}

}  // namespace

void add_map_command(CLI::App &app) {
  auto *map = app.add_subcommand("map", "inspect, make and export map snapshots (the service's state)");
  map->require_subcommand(1);

  auto info_file = std::make_shared<std::string>();
  auto *info = map->add_subcommand("info", "print a snapshot's version, map size, pose and counters");
  info->add_option("file", *info_file, "snapshot file")->required();
  info->callback([info_file] { print_info(*info_file); });

  struct SaveOptions {
    std::string run_dir, file, config;
  };
  auto save_options = std::make_shared<SaveOptions>();
  auto *save_command =
      map->add_subcommand("save", "make a snapshot from an `omnislam replay` output directory");
  save_command->add_option("run", save_options->run_dir, "output directory of omnislam replay")->required();
  save_command->add_option("file", save_options->file, "snapshot file to write")->required();
  save_command->add_option("--config", save_options->config, "the configuration of the run (for its hash)");
  save_command->callback(
      [save_options] { save(save_options->run_dir, save_options->file, save_options->config); });

  auto load_file = std::make_shared<std::string>();
  auto load_dir = std::make_shared<std::string>();
  auto *load_command = map->add_subcommand("load", "export a snapshot's map as map.csv and map.ply");
  load_command->add_option("file", *load_file, "snapshot file")->required();
  load_command->add_option("--out", *load_dir, "output directory")->required();
  load_command->callback([load_file, load_dir] { load(*load_file, *load_dir); });

  struct ExportOptions {
    std::string source, out_dir;
    double resolution_m = grid::GridConfig{}.resolution_m;
  };
  auto export_options = std::make_shared<ExportOptions>();
  auto *export_command = map->add_subcommand(
      "export", "write map.yaml + map.pgm (nav2_map_server) from a snapshot or a replay's output directory");
  export_command->add_option("source", export_options->source, "snapshot file or replay output directory")
      ->required();
  export_command->add_option("--out", export_options->out_dir, "output directory")->required();
  export_command
      ->add_option("--resolution", export_options->resolution_m,
                   "cell size (m) for a snapshot without an occupancy grid (its points only)")
      ->check(CLI::PositiveNumber);
  export_command->callback([export_options] {
    export_map(export_options->source, export_options->out_dir, export_options->resolution_m);
  });
}

}  // namespace omnislam::app
