#include "service_input.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <vector>

#include "dataset_source.hpp"
#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"
#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::app {
namespace {

double system_time_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Live frames are stamped with the system clock (ROS time), so DDS odometry matches them.
void attach_dds_odometry(pipeline::Frame &frame, dds::OdometryReader *odometry) {
  if (odometry == nullptr) return;
  odometry->poll();
  if (const auto T = odometry->at(frame.stamp_s)) {
    frame.T_odom_base = *T;
    frame.has_odometry = true;
  }
}

pipeline::FrameSource directory_source(const std::filesystem::path &dir, const mirror::MirrorConfig &camera,
                                       int loops, std::shared_ptr<dds::OdometryReader> odometry) {
  std::vector<std::filesystem::path> files;
  for (const auto &entry : std::filesystem::directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".png" || ext == ".bmp" || ext == ".jpg" || ext == ".pgm" || ext == ".tif")
      files.push_back(entry.path());
  }
  if (files.empty()) throw std::runtime_error(dir.string() + ": no images (png, bmp, jpg, pgm, tif)");
  std::sort(files.begin(), files.end());
  auto next = std::make_shared<std::size_t>(0);
  return [files, camera, loops, odometry, next]() -> pipeline::FramePtr {
    if (*next >= files.size() * static_cast<std::size_t>(loops)) return nullptr;
    auto frame = std::make_unique<pipeline::Frame>();
    frame->stamp_s = system_time_s();
    try {
      frame->image = io::read_camera_image(files[(*next)++ % files.size()], camera);
    } catch (const std::exception &error) {
      frame->error = error.what();
    }
    attach_dds_odometry(*frame, odometry.get());
    return frame;
  };
}

pipeline::FrameSource capture_source(std::shared_ptr<cv::VideoCapture> capture,
                                     std::shared_ptr<dds::OdometryReader> odometry) {
  return [capture, odometry]() -> pipeline::FramePtr {
    cv::Mat image;
    if (!capture->read(image) || image.empty()) return nullptr;  // end of video or camera gone
    auto frame = std::make_unique<pipeline::Frame>();
    frame->stamp_s = system_time_s();
    if (image.channels() == 3) {
      cv::cvtColor(image, frame->image, cv::COLOR_BGR2GRAY);
    } else {
      frame->image = image;
    }
    attach_dds_odometry(*frame, odometry.get());
    return frame;
  };
}

}  // namespace

ServiceInput make_service_input(io::Config &config, std::shared_ptr<dds::OdometryReader> odometry,
                                double resume_after_s) {
  const io::InputConfig &input = config.service.input;
  if (input.odometry != "dds") odometry.reset();
  ServiceInput result;
  result.rate_hz = std::max(0.0, input.rate_hz);
  if (input.source == "dataset") {
    const io::DatasetInfo info = io::read_dataset_info(input.path);
    config.scan.camera = info.camera;
    config.scan.camera_height_m = info.camera_height_m;
    if (input.rate_hz < 0.0) result.rate_hz = info.rate_hz;
    std::vector<Eigen::Isometry2d> poses(static_cast<std::size_t>(info.frames),
                                         Eigen::Isometry2d::Identity());
    if (input.odometry == "dataset") poses = io::to_isometries(io::read_tum_file(info.odometry));
    if (static_cast<int>(poses.size()) < info.frames)
      throw std::runtime_error(info.odometry.string() + ": too few poses");
    DatasetSourceOptions options;
    options.loops = input.loops;
    // Played round again, the robot drives from the last pose back to the first: the
    // odometry stays continuous (without ground truth it jumps back, a kidnapping).
    poses.resize(static_cast<std::size_t>(info.frames));
    if (input.loops > 1 && input.odometry == "dataset" && !info.groundtruth.empty()) {
      std::vector<Eigen::Isometry2d> truth = io::to_isometries(io::read_tum_file(info.groundtruth));
      if (truth.size() >= poses.size()) truth.resize(poses.size());
      options.seam = io::loop_seam(poses, truth);
    }
    options.after_s = resume_after_s;
    result.source = dataset_source(info, std::move(poses), config.scan.camera, std::move(options));
    result.description = "dataset " + info.dir.string();
  } else if (input.source == "directory") {
    if (input.rate_hz < 0.0) result.rate_hz = 10.0;
    result.source = directory_source(input.path, config.scan.camera, input.loops, odometry);
    result.description = "images in " + input.path;
  } else {
    auto capture = input.source == "camera" ? std::make_shared<cv::VideoCapture>(input.device)
                                            : std::make_shared<cv::VideoCapture>(input.path);
    if (!capture->isOpened()) {
      throw std::runtime_error("cannot open " + (input.source == "camera"
                                                     ? "camera " + std::to_string(input.device)
                                                     : input.path));
    }
    if (input.rate_hz < 0.0) result.rate_hz = 0.0;  // the device paces itself
    result.source = capture_source(std::move(capture), odometry);
    result.description =
        input.source == "camera" ? "camera " + std::to_string(input.device) : "video " + input.path;
  }
  return result;
}

pipeline::FrameSource with_initial_pose(pipeline::FrameSource source,
                                        std::shared_ptr<dds::InitialPoseReader> reader, std::string map_frame,
                                        std::shared_ptr<InitialPoseCounts> counts) {
  return [source = std::move(source), reader, map_frame, counts]() -> pipeline::FramePtr {
    pipeline::FramePtr frame = source();
    if (!frame) return frame;
    for (const dds::InitialPose &pose : reader->poll()) {
      if (pose.frame_id != map_frame) {
        const std::string reason = "initial pose ignored: frame_id '" + pose.frame_id + "', expected '" +
                                   map_frame + "' (dds.tf.map_frame)";
        spdlog::warn("{}", reason);
        counts->reject(reason);
        continue;
      }
      frame->pose_reset = pipeline::Frame::PoseReset{pose.T_map_base, pose.covariance};  // the newest wins
      counts->applied.fetch_add(1, std::memory_order_relaxed);
      spdlog::info("initial pose: x {:.3f} m, y {:.3f} m, yaw {:.2f} deg in {}, from the frame at t {:.3f} s",
                   pose.T_map_base.translation().x(), pose.T_map_base.translation().y(),
                   slam::yaw_rad_of(pose.T_map_base) * 180.0 / std::numbers::pi, map_frame, frame->stamp_s);
    }
    return frame;
  };
}

}  // namespace omnislam::app
