#include "relocalization_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/slam/planar_pose.hpp"
#include "omnislam/slam/relocalizer.hpp"
#include "omnislam/slam/slam.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"
#include "scan_truth.hpp"

namespace omnislam::test {

LocalizationRun build_localization_run(const std::filesystem::path &dir) {
  const TruthDataset data = load_truth_dataset(dir);
  stereo::ScanConfig config;
  config.camera = data.info.camera;
  config.camera_height_m = data.info.camera_height_m;
  stereo::ScanReconstructor reconstructor(config);
  LocalizationRun run;
  run.odometry = io::relative_to_first(io::to_isometries(io::read_tum_file(data.info.odometry)));
  if (run.odometry.size() < data.images.size())
    throw std::runtime_error(dir.string() + ": fewer odometry poses than frames");
  slam::Slam slam;
  for (std::size_t i = 0; i < data.images.size(); ++i) {
    slam::Points2 points;
    for (const stereo::ScanPoint &p : reconstructor.reconstruct(data.images[i]).points)
      points.emplace_back(p.x_m, p.y_m);
    (void)slam.process(points, run.odometry[i]);
    run.scans.push_back(std::move(points));
  }
  for (const slam::MapPoint &p : slam.map().points()) run.map.push_back(p.position_m);
  run.mapped = slam.trajectory();
  if (run.mapped.size() != run.scans.size())
    throw std::runtime_error(dir.string() + ": the mapping run left no pose for some frames");
  return run;
}

RelocalizationOutcome relocalize_from_every_frame(const LocalizationRun &run, int max_frames) {
  return relocalize_from_frames(run, max_frames, 0, static_cast<int>(run.scans.size()));
}

RelocalizationOutcome relocalize_from_frames(const LocalizationRun &run, int max_frames, int first,
                                             int last) {
  RelocalizationOutcome outcome;
  const int frames = static_cast<int>(run.scans.size());
  for (int start = std::max(first, 0); start < last && start + max_frames <= frames; ++start) {
    slam::Relocalizer relocalizer(run.map);
    ++outcome.starts;
    const int localized_before = outcome.localized;
    for (int f = start; f < start + max_frames; ++f) {
      const auto index = static_cast<std::size_t>(f);
      const auto begin = std::chrono::steady_clock::now();
      const slam::LocalizationResult result = relocalizer.process(run.scans[index], run.odometry[index]);
      outcome.frame_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count());
      if (result.state != slam::LocalizationState::kLocalized) continue;
      const Eigen::Isometry2d error = run.mapped[index].inverse() * result.T_map_base;
      const double error_m = error.translation().norm();
      const double error_deg = std::abs(slam::yaw_rad_of(error)) * 180.0 / std::numbers::pi;
      ++outcome.localized;
      outcome.frames_needed += f - start + 1;
      if (error_m <= 0.05 && error_deg <= 1.0) {
        ++outcome.correct;
        outcome.worst_error_m = std::max(outcome.worst_error_m, error_m);
        outcome.worst_error_deg = std::max(outcome.worst_error_deg, error_deg);
      } else {
        ++outcome.wrong;
        std::printf("  wrong pose: start %d, frame %d: %.3f m, %.2f deg off\n", start + 1, f + 1, error_m,
                    error_deg);
      }
      break;
    }
    if (outcome.localized == localized_before) outcome.missed.push_back(start + 1);
  }
  return outcome;
}

}  // namespace omnislam::test
