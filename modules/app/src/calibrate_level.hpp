#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam calibrate level IMAGE... [--config FILE] --out FILE` under
/// `calibrate`: the rig's tilt off level from the floor its images show (calib/level_fit.hpp),
/// no target. Each pass reconstructs every image with the tilt found so far, ranges the
/// floor contacts by stereo and fits the floor plane to them; the passes stop when the
/// correction is a tenth of its uncertainty. Writes `camera: {level_tilt_deg: [x, y]}` for
/// --config and dataset.yaml. An image without floor contacts is skipped with a message; an
/// unreadable or wrong-size image, or too few contacts over all, is an error: nothing written.
void add_calibrate_level(CLI::App &calibrate);

}  // namespace omnislam::app
