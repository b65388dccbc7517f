#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam calibrate rim IMAGE... [--config FILE] --out FILE`: the image centre
/// from the mirror's rim and central disc in the rig's own images (calib/rim.hpp), written
/// as YAML (`camera: {center_px: [u, v]}`) that --config and dataset.yaml read.
void add_calibrate_command(CLI::App &app);

}  // namespace omnislam::app
