#pragma once

#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <vector>

// For tests that edit snapshot bytes (io/snapshot.hpp format): make the header's payload
// size and CRC-32 match the bytes again, so the edit reaches the payload parser.
namespace omnislam::test {

/// `bytes` must hold at least the 24-byte header.
inline void reseal_snapshot(std::vector<std::uint8_t> &bytes) {
  const std::uint64_t payload = bytes.size() - 24;
  for (int i = 0; i < 8; ++i)
    bytes[12 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(payload >> (8 * i));
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, bytes.data() + 8, 12);
  crc = crc32(crc, bytes.data() + 24, static_cast<uInt>(payload));
  for (int i = 0; i < 4; ++i)
    bytes[20 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
}

}  // namespace omnislam::test
