#pragma once

#include <cstdint>
#include <random>

// The random streams of the degradation (private to degrade/). Each stream's generator is
// seeded from (seed, stream, frame) alone, so a frame's draws never depend on which
// frames were degraded before it, or on which thread.

namespace omnislam::degrade::detail {

enum class Stream : std::uint64_t { kExposure = 1, kDust = 2, kNoise = 3 };

// splitmix64 (Steele, Lea, Flood 2014): a bijective 64-bit mixer, so nearby seeds and
// frame numbers give unrelated generator states.
[[nodiscard]] constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

[[nodiscard]] inline std::mt19937_64 generator(std::uint64_t seed, Stream stream, std::int64_t frame) {
  const std::uint64_t key = splitmix64(splitmix64(splitmix64(seed) ^ static_cast<std::uint64_t>(stream)) ^
                                       static_cast<std::uint64_t>(frame));
  return std::mt19937_64(key);
}

/// Uniform in [0, 1) from the top 53 bits of one draw.
[[nodiscard]] inline double uniform01(std::mt19937_64 &rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

[[nodiscard]] inline double uniform(std::mt19937_64 &rng, double low, double high) {
  return low + (high - low) * uniform01(rng);
}

}  // namespace omnislam::degrade::detail
