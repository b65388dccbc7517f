#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.hpp"
#include "omnislam/io/config.hpp"

// load_config on arbitrary bytes: a configuration or a ConfigError, nothing else (no other
// exception type, no crash, no sanitizer finding).
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    (void)omnislam::io::load_config(omnislam::fuzz::input_file(data, size, ".yaml"));
  } catch (const omnislam::io::ConfigError &) {
  }
  return 0;
}
