#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam degrade DATASET --out DIR [--factors LIST] [--seed N] [--config FILE]`:
/// a copy of the dataset with every frame image degraded (degrade/degradation.hpp).
void add_degrade_command(CLI::App &app);

}  // namespace omnislam::app
