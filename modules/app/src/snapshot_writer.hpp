#pragma once

#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "omnislam/io/snapshot.hpp"

// Writes omnislamd's periodic snapshots on a thread of its own, so that a slow disk
// (fsync) never holds up the pipeline. Only the newest snapshot matters: one submitted
// while another waits replaces it.
namespace omnislam::app {

class SnapshotWriter {
 public:
  explicit SnapshotWriter(std::filesystem::path file);
  SnapshotWriter(const SnapshotWriter &) = delete;
  SnapshotWriter &operator=(const SnapshotWriter &) = delete;
  /// finish()
  ~SnapshotWriter();

  /// Queues `snapshot` for writing (io::write_snapshot: atomic, fsynced). Never blocks on I/O.
  void submit(io::Snapshot snapshot);
  /// Writes what is still queued and stops the thread. Idempotent.
  void finish();

  [[nodiscard]] const std::filesystem::path &file() const { return file_; }
  [[nodiscard]] std::uint64_t written() const;
  /// The last write error (file and system call), empty after a successful write.
  [[nodiscard]] std::string last_error() const;

 private:
  void loop();

  std::filesystem::path file_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<io::Snapshot> pending_;
  bool stopping_ = false;
  std::uint64_t written_ = 0;
  std::string last_error_;
  std::thread thread_;
};

}  // namespace omnislam::app
