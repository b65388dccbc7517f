#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam calibrate target IMAGE... [--config FILE] [--squares 8x6]
/// [--square-mm 45] --out FILE` under `calibrate`: every rig parameter from a printed
/// chessboard held round the robot and laid on the floor (calib/target_fit.hpp), with a
/// report of each parameter's uncertainty, and YAML (`camera:` keys) for --config and
/// dataset.yaml. Images without the board are skipped with a message; an unreadable or
/// wrong-size image, too few views or no board on the floor is an error: nothing written.
void add_calibrate_target(CLI::App &calibrate);

}  // namespace omnislam::app
