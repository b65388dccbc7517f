#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_input_file.hpp"
#include "omnislam/io/ground_truth_files.hpp"

// read_tum_file: poses that are finite and in time order, or a std::runtime_error.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    const auto poses = omnislam::io::read_tum_file(omnislam::fuzz::input_file(data, size, ".tum"));
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (!std::isfinite(poses[i].yaw_rad()) || (i > 0 && poses[i].t_s < poses[i - 1].t_s)) std::abort();
    }
  } catch (const std::runtime_error &) {
  }
  return 0;
}
