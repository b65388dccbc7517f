#include "snapshot_writer.hpp"

#include <spdlog/spdlog.h>

#include <exception>
#include <utility>

namespace omnislam::app {

SnapshotWriter::SnapshotWriter(std::filesystem::path file)
    : file_(std::move(file)), thread_([this] { loop(); }) {}

SnapshotWriter::~SnapshotWriter() { finish(); }

void SnapshotWriter::submit(io::Snapshot snapshot) {
  {
    const std::lock_guard lock(mutex_);
    pending_ = std::move(snapshot);
  }
  wake_.notify_one();
}

void SnapshotWriter::finish() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

std::uint64_t SnapshotWriter::written() const {
  const std::lock_guard lock(mutex_);
  return written_;
}

std::string SnapshotWriter::last_error() const {
  const std::lock_guard lock(mutex_);
  return last_error_;
}

void SnapshotWriter::loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return pending_ || stopping_; });
    if (!pending_) return;  // stopping with nothing left to write
    io::Snapshot snapshot = std::move(*pending_);
    pending_.reset();
    lock.unlock();
    std::string error;
    try {
      io::write_snapshot(file_, snapshot);
    } catch (const std::exception &failure) {
      error = failure.what();
    }
    lock.lock();
    if (error.empty()) {
      ++written_;
      if (!last_error_.empty()) spdlog::info("snapshots are written again to {}", file_.string());
    } else if (error != last_error_) {
      spdlog::error("snapshot not saved: {}", error);  // logged once per distinct error
    }
    last_error_ = error;
  }
}

}  // namespace omnislam::app
