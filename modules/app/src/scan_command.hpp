#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam scan IMAGE [--config FILE]`: reconstructs the local scan of one
/// omnidirectional image and prints it as CSV on stdout (architecture.md contract:
/// header `azimuth_deg,range_m,x_m,y_m,z_m,inner_row,outer_row`), a summary on stderr.
void add_scan_command(CLI::App &app);

}  // namespace omnislam::app
