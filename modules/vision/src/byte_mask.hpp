#pragma once

#include <bit>
#include <cstdint>

namespace omnislam::vision {

/// The byte (in memory order) of a word's lowest set bit: with eight bytes of a row loaded
/// into a word and masked, the loops that skip eight pixels at a time find the few that
/// matter without a branch per pixel.
inline int byte_of_lowest_bit(std::uint64_t word) {
  const int byte = std::countr_zero(word) / 8;
  return std::endian::native == std::endian::little ? byte : 7 - byte;
}

}  // namespace omnislam::vision
