#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_input_file.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/io/run_files.hpp"

// read_map_csv and read_floorplan_csv on the same bytes: finite values (and hits >= 1), or
// a std::runtime_error.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const auto file = omnislam::fuzz::input_file(data, size, ".csv");
  try {
    for (const auto &p : omnislam::io::read_map_csv(file)) {
      if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m) || p.hits < 1) std::abort();
    }
  } catch (const std::runtime_error &) {
  }
  try {
    for (const auto &s : omnislam::io::read_floorplan_csv(file)) {
      if (!std::isfinite(s.x1_m + s.y1_m + s.x2_m + s.y2_m)) std::abort();
    }
  } catch (const std::runtime_error &) {
  }
  return 0;
}
