#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

// The parsers under test read files: each input is written to one scratch file per process.
namespace omnislam::fuzz {

inline std::filesystem::path input_file(const std::uint8_t *data, std::size_t size, const char *extension) {
  // In memory when /dev/shm exists: a disk write per input would dominate the run time.
  static const std::filesystem::path dir =
      std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
  static const std::filesystem::path file = dir / ("omnislam-fuzz-" + std::to_string(::getpid()) + extension);
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char *>(data), static_cast<std::streamsize>(size));
  return file;
}

}  // namespace omnislam::fuzz
