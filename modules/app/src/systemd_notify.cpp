#include "systemd_notify.hpp"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <cstdint>
#include <cstring>

namespace omnislam::app {
namespace {

void notify(const std::string &message) {
  const int result = sd_notify(0, message.c_str());
  if (result < 0) spdlog::warn("sd_notify failed: {}", std::strerror(-result));
}

}  // namespace

SystemdNotifier::SystemdNotifier() {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) interval_ = std::chrono::microseconds(usec);
}

void SystemdNotifier::ready(const std::string &status) const { notify("READY=1\nSTATUS=" + status); }

void SystemdNotifier::status(const std::string &status) const { notify("STATUS=" + status); }

void SystemdNotifier::watchdog() const { notify("WATCHDOG=1"); }

void SystemdNotifier::stopping(const std::string &status) const { notify("STOPPING=1\nSTATUS=" + status); }

}  // namespace omnislam::app
