#pragma once

#include <chrono>
#include <string>

// systemd's notification protocol (sd_notify, libsystemd) for omnislamd: READY, STATUS,
// WATCHDOG, STOPPING. Every call is a no-op when the service does not run under systemd
// (no NOTIFY_SOCKET), so the same binary runs from a shell.
namespace omnislam::app {

class SystemdNotifier {
 public:
  /// Reads WATCHDOG_USEC / WATCHDOG_PID (sd_watchdog_enabled).
  SystemdNotifier();

  /// WatchdogSec is set for this process: watchdog() must be called more often than
  /// watchdog_interval().
  [[nodiscard]] bool watchdog_enabled() const { return interval_.count() > 0; }
  [[nodiscard]] std::chrono::microseconds watchdog_interval() const { return interval_; }

  void ready(const std::string &status) const;
  void status(const std::string &status) const;
  void watchdog() const;
  void stopping(const std::string &status) const;

 private:
  std::chrono::microseconds interval_{0};
};

}  // namespace omnislam::app
