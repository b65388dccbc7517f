#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "omnislam/io/snapshot.hpp"

// decode_snapshot on arbitrary bytes: a snapshot or a SnapshotError. A random header almost
// never has the right magic, size and CRC, so for inputs starting with an even byte the
// header is repaired first, which lets the fuzzer explore the payload parser. A decoded
// snapshot must encode and decode again to the same content.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  if (size >= 24 && data[0] % 2 == 0) {
    std::memcpy(bytes.data(), "OMNISNAP", 8);
    const std::uint64_t payload = size - 24;
    for (int i = 0; i < 8; ++i)
      bytes[12 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(payload >> (8 * i));
    uLong crc = crc32(0L, Z_NULL, 0);
    crc = crc32(crc, bytes.data() + 8, 12);
    crc = crc32(crc, bytes.data() + 24, static_cast<uInt>(payload));
    for (int i = 0; i < 4; ++i)
      bytes[20 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
  }
  try {
    const omnislam::io::Snapshot snapshot = omnislam::io::decode_snapshot(bytes, "fuzz.snap");
    const omnislam::io::Snapshot again =
        omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(snapshot), "again.snap");
    if (again.points.size() != snapshot.points.size() || again.counters.frames != snapshot.counters.frames ||
        again.config_hash != snapshot.config_hash) {
      std::abort();
    }
  } catch (const omnislam::io::SnapshotError &) {
  }
  return 0;
}
