#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam evaluate RUN_DIR DATASET`: trajectory error of the run and of the
/// dataset's odometry alone, and map error against floorplan.csv; prints them and writes
/// RUN_DIR/evaluation.json and RUN_DIR/errors.csv (per frame).
void add_evaluate_command(CLI::App &app);

}  // namespace omnislam::app
