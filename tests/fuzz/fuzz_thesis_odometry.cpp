#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_input_file.hpp"
#include "omnislam/io/ground_truth_files.hpp"

// read_thesis_odometry: finite poses, or a std::runtime_error.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    for (const auto &pose :
         omnislam::io::read_thesis_odometry(omnislam::fuzz::input_file(data, size, ".txt"))) {
      if (!std::isfinite(pose.x_m) || !std::isfinite(pose.y_m)) std::abort();
    }
  } catch (const std::runtime_error &) {
  }
  return 0;
}
