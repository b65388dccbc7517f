#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "omnislam/io/snapshot.hpp"
#include "snapshot_bytes.hpp"

// decode_snapshot on arbitrary bytes: a snapshot or a SnapshotError. A random header almost
// never has the right magic, size and CRC, so for inputs starting with an even byte the
// header is repaired first, which lets the fuzzer explore the payload parser. A decoded
// snapshot (keyframe graph included, version 4) must encode and decode again to the same content.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  if (size >= 24 && data[0] % 2 == 0) {
    std::memcpy(bytes.data(), "OMNISNAP", 8);
    omnislam::test::reseal_snapshot(bytes);
  }
  try {
    const omnislam::io::Snapshot snapshot = omnislam::io::decode_snapshot(bytes, "fuzz.snap");
    const omnislam::io::Snapshot again =
        omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(snapshot), "again.snap");
    const auto keyframes = [](const omnislam::io::Snapshot &s) {
      return s.graph ? s.graph->keyframes.size() : 0;
    };
    const auto edges = [](const omnislam::io::Snapshot &s) { return s.graph ? s.graph->edges.size() : 0; };
    if (again.points.size() != snapshot.points.size() || again.counters.frames != snapshot.counters.frames ||
        again.config_hash != snapshot.config_hash || again.graph.has_value() != snapshot.graph.has_value() ||
        keyframes(again) != keyframes(snapshot) || edges(again) != edges(snapshot)) {
      std::abort();
    }
  } catch (const omnislam::io::SnapshotError &) {
  }
  return 0;
}
