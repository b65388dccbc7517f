#pragma once

#include <memory>
#include <string>

#include "omnislam/dds/odometry_reader.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/pipeline/pipeline.hpp"

// omnislamd's inputs (config `input:`): frames from a dataset, an image directory, a
// camera or a video, with odometry from the dataset, DDS (rt/odom) or none.
namespace omnislam::app {

struct ServiceInput {
  pipeline::FrameSource source;
  double rate_hz = 0.0;  ///< pacing for the pipeline's capture stage (0: the source paces itself)
  std::string description;
};

/// Builds the source. `config.scan.camera` is updated from a dataset's own camera.
/// `odometry` is used (on the capture thread only) when input.odometry is dds. A dataset
/// starts after `resume_after_s` (the time of the snapshot the service resumed from);
/// live sources are stamped with the clock and need no such cut.
/// Throws std::runtime_error naming the path or device that cannot be opened.
[[nodiscard]] ServiceInput make_service_input(io::Config &config,
                                              std::shared_ptr<dds::OdometryReader> odometry,
                                              double resume_after_s);

}  // namespace omnislam::app
