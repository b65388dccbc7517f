#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// `omnislam profile PROFILE.csv`: per-stage statistics beside the thesis's 2008 shares.
void add_profile_command(CLI::App &app);

}  // namespace omnislam::app
