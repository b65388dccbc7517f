#pragma once

#include <CLI/CLI.hpp>

namespace omnislam::app {

/// `omnislam echo TOPIC`: print what arrives on one of omnislam's DDS topics.
void add_echo_command(CLI::App &app);

}  // namespace omnislam::app
