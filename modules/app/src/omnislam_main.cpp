#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "calibrate_command.hpp"
#include "degrade_command.hpp"
#include "echo_command.hpp"
#include "evaluate_command.hpp"
#include "map_command.hpp"
#include "mirror_lut_command.hpp"
#include "omnislam/io/config.hpp"
#include "profile_command.hpp"
#include "replay_command.hpp"
#include "scan_command.hpp"

int main(int argc, char **argv) {
  CLI::App app{"omnislam: omnidirectional stereo SLAM tools"};
  app.require_subcommand(1);
  omnislam::app::add_mirror_lut_command(app);
  omnislam::app::add_scan_command(app);
  omnislam::app::add_replay_command(app);
  omnislam::app::add_evaluate_command(app);
  omnislam::app::add_degrade_command(app);
  omnislam::app::add_map_command(app);
  omnislam::app::add_profile_command(app);
  omnislam::app::add_echo_command(app);
  omnislam::app::add_calibrate_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &error) {
    return app.exit(error);
  } catch (const omnislam::io::ConfigError &error) {
    // Exit code 2: the configuration is wrong; a restart (systemd) would not help.
    std::fprintf(stderr, "omnislam: configuration error: %s\n", error.what());
    return 2;
  } catch (const std::exception &error) {
    std::fprintf(stderr, "omnislam: error: %s\n", error.what());
    return 1;
  }
  return 0;
}
