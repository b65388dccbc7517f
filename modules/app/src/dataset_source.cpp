#include "dataset_source.hpp"

#include <exception>
#include <memory>
#include <stdexcept>
#include <utility>

#include "omnislam/io/image_file.hpp"
#include "omnislam/io/poses.hpp"

namespace omnislam::app {

pipeline::FrameSource dataset_source(const io::DatasetInfo &info, std::vector<Eigen::Isometry2d> odometry,
                                     const mirror::MirrorConfig &camera, DatasetSourceOptions options) {
  auto next = std::make_shared<int>(0);
  return [info, odometry = std::move(odometry), camera, options = std::move(options), next]() {
    const int frames = info.frames;
    while (*next < frames * options.loops && *next / info.rate_hz <= options.after_s) ++*next;
    if (frames <= 0 || *next >= frames * options.loops) return pipeline::FramePtr();
    const int index = (*next)++;
    const int frame_number = index % frames + 1;
    auto frame = std::make_unique<pipeline::Frame>();
    frame->stamp_s = index / info.rate_hz;
    frame->T_odom_base = io::looped_odometry(odometry, options.seam, static_cast<std::size_t>(index));
    frame->has_odometry = true;
    try {
      frame->image = io::read_camera_image(info.image(frame_number), camera);
      if (options.degrader) {
        degrade::Degraded degraded = options.degrader->apply(frame->image, frame_number);
        if (!degraded.ok())
          throw std::runtime_error(info.image(frame_number).string() + ": " + degraded.error);
        frame->image = std::move(degraded.image);
      }
    } catch (const std::exception &error) {
      frame->error = error.what();
      if (options.on_skip) options.on_skip(frame_number, frame->error);
    }
    return frame;
  };
}

pipeline::FrameSource memory_source(std::vector<cv::Mat> images, std::vector<Eigen::Isometry2d> odometry,
                                    double rate_hz, int loops) {
  auto next = std::make_shared<std::size_t>(0);
  return [images = std::move(images), odometry = std::move(odometry), rate_hz, loops, next]() {
    if (images.empty() || *next >= images.size() * static_cast<std::size_t>(loops))
      return pipeline::FramePtr();
    const std::size_t index = (*next)++;
    auto frame = std::make_unique<pipeline::Frame>();
    frame->stamp_s = static_cast<double>(index) / rate_hz;
    frame->T_odom_base = odometry[index % images.size()];
    frame->has_odometry = true;
    frame->image = images[index % images.size()];  // shared, read-only downstream
    return frame;
  };
}

}  // namespace omnislam::app
