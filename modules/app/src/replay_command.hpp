#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam replay DATASET [--config FILE] --out DIR [--odometry-noise thesis --seed N]
/// [--degrade LIST [--degrade-seed N]]`.
void add_replay_command(CLI::App &app);

}  // namespace omnislam::app
