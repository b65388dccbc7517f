#include <catch2/catch.hpp>
#include <filesystem>
#include <thread>

#include "snapshot_writer.hpp"

// omnislamd's snapshot writer thread: the newest snapshot wins, nothing is lost at finish(),
// a failing disk is reported without stopping the service. Label `concurrency` (TSan).
namespace fs = std::filesystem;
using omnislam::app::SnapshotWriter;
using omnislam::io::Snapshot;

namespace {

fs::path scratch(const std::string &name) {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-snapshot-writer" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Snapshot numbered(std::uint64_t n) {
  Snapshot s;
  s.t_s = static_cast<double>(n);
  s.counters.frames = n;
  s.map_integrations = 1;
  for (std::uint64_t i = 0; i < 200; ++i) s.points.push_back({{0.01 * static_cast<double>(i), 1.0}, 1, 1});
  return s;
}

}  // namespace

TEST_CASE("snapshot writer: a stream of snapshots ends with the last one on disk", "[app][concurrency]") {
  const fs::path file = scratch("stream") / "state.omnisnap";
  SnapshotWriter writer(file);
  constexpr std::uint64_t kCount = 500;
  std::thread producer([&] {
    for (std::uint64_t n = 1; n <= kCount; ++n) writer.submit(numbered(n));
  });
  producer.join();
  writer.finish();
  writer.finish();  // idempotent
  CHECK(writer.last_error().empty());
  CHECK(writer.written() >= 1);
  CHECK(writer.written() <= kCount);  // snapshots queued behind a write are replaced, not queued
  const Snapshot read = omnislam::io::read_snapshot(file);
  CHECK(read.counters.frames == kCount);
  CHECK(read.points.size() == 200);
}

TEST_CASE("snapshot writer: a write that fails is reported and the next one still tried",
          "[app][concurrency]") {
  const fs::path dir = scratch("fails");
  const fs::path file = dir / "missing" / "state.omnisnap";  // its directory does not exist
  SnapshotWriter writer(file);
  writer.submit(numbered(1));
  while (writer.last_error().empty()) std::this_thread::yield();
  CHECK_THAT(writer.last_error(), Catch::Contains(file.parent_path().string()));
  CHECK(writer.written() == 0);
  fs::create_directories(file.parent_path());
  writer.submit(numbered(2));
  writer.finish();
  CHECK(writer.last_error().empty());
  CHECK(writer.written() == 1);
  CHECK(omnislam::io::read_snapshot(file).counters.frames == 2);
}
