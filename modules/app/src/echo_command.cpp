#include "echo_command.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

#include "omnislam/dds/echo.hpp"

namespace omnislam::app {
namespace {

std::atomic<bool> g_stop{false};  // set by SIGINT/SIGTERM: a signal handler can reach nothing else

extern "C" void on_signal(int) { g_stop.store(true); }

struct EchoArgs {
  std::string topic;
  int domain_id = 0;
  std::string dds_config;
  dds::EchoOptions options;
};

}  // namespace

void add_echo_command(CLI::App &app) {
  auto *command = app.add_subcommand("echo", "subscribe to a DDS topic and print what arrives");
  auto args = std::make_shared<EchoArgs>();
  command
      ->add_option("topic", args->topic,
                   "omnislam/pose, omnislam/map, omnislam/scan, omnislam/profile, "
                   "omnislam/status or odom (with or without rt/)")
      ->required();
  command->add_option("--domain", args->domain_id, "DDS domain id");
  command->add_option("--dds-config", args->dds_config, "Cyclone DDS XML file (default: CYCLONEDDS_URI)");
  command->add_option("--count", args->options.max_messages, "exit after this many messages");
  command->add_option("--timeout", args->options.timeout_s, "exit after this many seconds");
  command->callback([args] {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const dds::Participant participant({args->domain_id, args->dds_config});
    dds::echo(participant, args->topic, args->options, g_stop, stdout);
  });
}

}  // namespace omnislam::app
