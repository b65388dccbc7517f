// Registration side by side (SLAM issue): this project's Trimmed ICP (point-to-line and the
// thesis's point-to-point) against PCL's IterativeClosestPoint, on the same pairs of
// consecutive local scans of a dataset with the same initial guesses (the odometry step).
// Each method's relative poses are chained into a trajectory and compared with the ground
// truth. usage: bench_registration DATASET_DIR
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/slam/evaluation.hpp"
#include "omnislam/slam/planar_pose.hpp"
#include "omnislam/slam/trimmed_icp.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

namespace {

using omnislam::slam::Points2;

pcl::PointCloud<pcl::PointXYZ>::Ptr to_cloud(const Points2 &points) {
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto &p : points)
    cloud->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f));
  return cloud;
}

// Registers `sample` (this scan) onto `model` (the previous scan): T_model_sample.
using Registration = std::function<Eigen::Isometry2d(const Points2 &model, const Points2 &sample,
                                                     const Eigen::Isometry2d &guess)>;

Eigen::Isometry2d pcl_icp(const Points2 &model, const Points2 &sample, const Eigen::Isometry2d &guess) {
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setInputSource(to_cloud(sample));
  icp.setInputTarget(to_cloud(model));
  icp.setMaxCorrespondenceDistance(0.5);
  icp.setMaximumIterations(30);
  icp.setTransformationEpsilon(1e-8);
  Eigen::Matrix4f initial = Eigen::Matrix4f::Identity();
  initial.topLeftCorner<2, 2>() = guess.linear().cast<float>();
  initial.topRightCorner<2, 1>() = guess.translation().cast<float>();
  pcl::PointCloud<pcl::PointXYZ> aligned;
  icp.align(aligned, initial);
  const Eigen::Matrix4f T = icp.getFinalTransformation();
  return omnislam::slam::planar_pose(T(0, 3), T(1, 3), std::atan2(T(1, 0), T(0, 0)));
}

Registration trimmed_icp(omnislam::slam::IcpMetric metric) {
  return [metric](const Points2 &model, const Points2 &sample, const Eigen::Isometry2d &guess) {
    omnislam::slam::TrimmedIcpConfig config;
    config.metric = metric;
    const omnislam::slam::NearestNeighbors index(model);
    const auto result = omnislam::slam::register_trimmed_icp(index, sample, guess, config);
    return result.valid ? result.T_model_sample : guess;
  };
}

}  // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DATASET_DIR\n", argv[0]);
    return 2;
  }
  try {
    const auto info = omnislam::io::read_dataset_info(argv[1]);
    omnislam::stereo::ScanConfig scan_config;
    scan_config.camera = info.camera;
    scan_config.camera_height_m = info.camera_height_m;
    omnislam::stereo::ScanReconstructor reconstructor(scan_config);
    std::vector<Points2> scans;
    for (int frame = 1; frame <= info.frames; ++frame) {
      const auto scan =
          reconstructor.reconstruct(omnislam::io::read_camera_image(info.image(frame), info.camera));
      Points2 points;
      for (const auto &p : scan.points) points.emplace_back(p.x_m, p.y_m);
      scans.push_back(std::move(points));
    }
    const auto truth = omnislam::io::relative_to_first(
        omnislam::io::to_isometries(omnislam::io::read_tum_file(info.groundtruth)));
    const auto odometry = omnislam::io::relative_to_first(
        omnislam::io::to_isometries(omnislam::io::read_tum_file(info.odometry)));
    std::printf("bench_registration %s: %zu consecutive scan pairs, initial guess = odometry step\n", argv[1],
                scans.size() - 1);
    std::printf("  %-34s %10s %10s %12s %12s\n", "method", "median ms", "p99 ms", "ATE max mm", "final mm");
    const std::vector<std::pair<std::string, Registration>> methods = {
        {"odometry only", [](const Points2 &, const Points2 &, const Eigen::Isometry2d &g) { return g; }},
        {"TrICP point-to-line (default)", trimmed_icp(omnislam::slam::IcpMetric::kPointToLine)},
        {"TrICP point-to-point (thesis)", trimmed_icp(omnislam::slam::IcpMetric::kPointToPoint)},
        {"PCL IterativeClosestPoint", pcl_icp},
    };
    for (const auto &[name, registration] : methods) {
      std::vector<double> ms;
      std::vector<Eigen::Isometry2d> chained = {Eigen::Isometry2d::Identity()};
      for (std::size_t i = 1; i < scans.size(); ++i) {
        const Eigen::Isometry2d guess = odometry[i - 1].inverse() * odometry[i];
        const auto start = std::chrono::steady_clock::now();
        const Eigen::Isometry2d step = registration(scans[i - 1], scans[i], guess);
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        chained.push_back(chained.back() * step);
      }
      std::sort(ms.begin(), ms.end());
      const auto error = omnislam::slam::trajectory_error(chained, truth);
      std::printf("  %-34s %10.3f %10.3f %12.1f %12.1f\n", name.c_str(), ms[ms.size() / 2],
                  ms[static_cast<std::size_t>(0.99 * (ms.size() - 1))], error.max_m * 1e3,
                  error.final_m * 1e3);
    }
  } catch (const std::exception &error) {
    std::fprintf(stderr, "bench_registration: %s\n", error.what());
    return 1;
  }
  return 0;
}
