#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam mirror-lut --out DIR`: writes the thesis's rP.txt / zP.txt
/// triangulation table for the default (thesis) camera and mirror and prints a summary.
void add_mirror_lut_command(CLI::App &app);

}  // namespace omnislam::app
