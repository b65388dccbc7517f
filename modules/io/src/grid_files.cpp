#include "omnislam/io/grid_files.hpp"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

namespace omnislam::io {
namespace {

constexpr unsigned char kOccupiedShade = 0;
constexpr unsigned char kFreeShade = 254;
constexpr unsigned char kUnknownShade = 205;

}  // namespace

void write_nav2_map(const std::filesystem::path &yaml_file, const grid::GridImage &image) {
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(yaml_file.string() + ": the grid is empty");
  std::filesystem::path pgm_file = yaml_file;
  pgm_file.replace_extension(".pgm");
  {
    std::ofstream pgm(pgm_file, std::ios::binary);
    pgm << "P5\n" << image.width << ' ' << image.height << "\n255\n";
    std::vector<unsigned char> row(static_cast<std::size_t>(image.width));
    for (int r = 0; r < image.height; ++r) {
      const int y = image.height - 1 - r;  // the image's top row is the grid's highest y
      for (int x = 0; x < image.width; ++x) {
        const std::int8_t cell =
            image.cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                        static_cast<std::size_t>(x)];
        row[static_cast<std::size_t>(x)] =
            cell == 100 ? kOccupiedShade : (cell == 0 ? kFreeShade : kUnknownShade);
      }
      pgm.write(reinterpret_cast<const char *>(row.data()), static_cast<std::streamsize>(row.size()));
    }
    if (!pgm) throw std::runtime_error(pgm_file.string() + ": cannot write");
  }
  std::ofstream yaml(yaml_file);
  char origin[96];
  std::snprintf(origin, sizeof origin, "[%.6f, %.6f, 0.0]", image.origin_m.x(), image.origin_m.y());
  yaml << "image: " << pgm_file.filename().string() << "\n"
       << "mode: trinary\n"
       << "resolution: " << image.resolution_m << "\n"
       << "origin: " << origin << "\n"
       << "negate: 0\n"
       << "occupied_thresh: 0.65\n"
       << "free_thresh: 0.196\n";
  if (!yaml) throw std::runtime_error(yaml_file.string() + ": cannot write");
}

grid::GridImage read_nav2_map(const std::filesystem::path &yaml_file) {
  const std::string name = yaml_file.string();
  YAML::Node root;
  try {
    root = YAML::LoadFile(name);
  } catch (const YAML::BadFile &) {
    throw std::runtime_error(name + ": cannot open the map file");
  } catch (const YAML::Exception &error) {
    throw std::runtime_error(name + ": not YAML: " + error.what());
  }
  if (!root.IsMap()) throw std::runtime_error(name + ": not a nav2 map file (no mapping)");
  const auto field = [&](const char *key) {
    const YAML::Node node = root[key];
    if (!node) throw std::runtime_error(name + ": missing key " + key);
    return node;
  };
  grid::GridImage image;
  std::filesystem::path image_file;
  std::string mode = "trinary";
  double occupied_thresh = 0.0, free_thresh = 0.0;
  bool negate = false;
  std::vector<double> origin;
  try {
    image_file = field("image").as<std::string>();
    image.resolution_m = field("resolution").as<double>();
    origin = field("origin").as<std::vector<double>>();
    occupied_thresh = field("occupied_thresh").as<double>();
    free_thresh = field("free_thresh").as<double>();
    negate = field("negate").as<int>() != 0;
    if (root["mode"]) mode = root["mode"].as<std::string>();
  } catch (const YAML::Exception &error) {
    throw std::runtime_error(name + ": bad value: " + error.what());
  }
  if (mode != "trinary") throw std::runtime_error(name + ": mode " + mode + " (only trinary maps are read)");
  if (origin.size() != 3) throw std::runtime_error(name + ": origin must be [x, y, yaw]");
  if (!(image.resolution_m > 0.0)) throw std::runtime_error(name + ": resolution must be > 0");
  image.origin_m = {origin[0], origin[1]};
  if (image_file.is_relative()) image_file = yaml_file.parent_path() / image_file;
  const cv::Mat pixels = cv::imread(image_file.string(), cv::IMREAD_GRAYSCALE);
  if (pixels.empty()) throw std::runtime_error(image_file.string() + ": not a readable image");
  image.width = pixels.cols;
  image.height = pixels.rows;
  image.cells.resize(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
  for (int r = 0; r < image.height; ++r) {
    const int y = image.height - 1 - r;
    for (int x = 0; x < image.width; ++x) {
      const double shade = pixels.at<unsigned char>(r, x);
      const double p = negate ? shade / 255.0 : (255.0 - shade) / 255.0;
      image.cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                  static_cast<std::size_t>(x)] = p > occupied_thresh ? 100 : (p < free_thresh ? 0 : -1);
    }
  }
  return image;
}

}  // namespace omnislam::io
