#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// Registers `omnislam map info FILE`, `omnislam map save RUN_DIR FILE [--config FILE]` and
/// `omnislam map load FILE --out DIR` (map snapshots, io/snapshot.hpp).
void add_map_command(CLI::App &app);

}  // namespace omnislam::app
