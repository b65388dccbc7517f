#include "scan_command.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "omnislam/io/config.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

namespace omnislam::app {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

struct ScanOptions {
  std::string image;
  std::string config;
  bool quiet = false;
  bool free = false;
};

void print_csv(const stereo::LocalScan &scan) {
  std::printf("azimuth_deg,range_m,x_m,y_m,z_m,inner_row,outer_row,floor_ranged,range_per_px_m,elevated\n");
  for (const stereo::ScanPoint &p : scan.points) {
    std::printf("%.3f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f,%d,%.5f,%d\n", p.azimuth_rad * kDegPerRad, p.range_m,
                p.x_m, p.y_m, p.z_m, static_cast<double>(p.inner_row), static_cast<double>(p.outer_row),
                p.floor_ranged ? 1 : 0, p.range_per_px_m, p.elevated ? 1 : 0);
  }
}

// Free floor per panorama column (floor-boundary scans), where it ended in a drop and how far
// the lower floor beyond was seen: "nan" where nothing was seen.
void print_free_csv(const stereo::LocalScan &scan, const mirror::MirrorConfig &camera) {
  std::printf("azimuth_deg,free_range_m,drop_range_m,drop_lower_range_m\n");
  const auto at = [](const std::vector<float> &ranges_m, std::size_t column) {
    return column < ranges_m.size() ? static_cast<double>(ranges_m[column])
                                    : std::numeric_limits<double>::quiet_NaN();
  };
  for (std::size_t column = 0; column < scan.free_range_m.size(); ++column) {
    const double azimuth_deg = mirror::column_azimuth_rad(camera, static_cast<int>(column)) * kDegPerRad;
    std::printf("%.3f,%.4f,%.4f,%.4f\n", azimuth_deg, at(scan.free_range_m, column),
                at(scan.drop_range_m, column), at(scan.drop_lower_range_m, column));
  }
}

void print_summary(const std::string &image, const stereo::LocalScan &scan) {
  const stereo::ScanStats &s = scan.stats;
  std::fprintf(stderr,
               "%s: candidates inner %d / outer %d, admissible pairs %d, matched %d, "
               "no intersection %d, outside cut-offs %d, filtered %d, points %d\n",
               image.c_str(), s.inner.candidates, s.outer.candidates, s.admissible_pairs, s.matched,
               s.no_intersection, s.outside_cutoffs, s.filtered_out, s.points);
  std::fprintf(stderr,
               "%s: noise %.2f grey levels; Canny high threshold inner %.1f / outer %.1f, raised by the "
               "noise to at most %.1f / %.1f\n",
               image.c_str(), static_cast<double>(s.image_noise_dn), s.inner.high_threshold,
               s.outer.high_threshold, std::max(s.inner.high_threshold, s.inner.noise_high_threshold),
               std::max(s.outer.high_threshold, s.outer.noise_high_threshold));
  if (!scan.free_range_m.empty()) {
    std::fprintf(stderr,
                 "%s: floor boundary: floor texture %d, floor contacts %d (undecided %d), elevated %d, "
                 "unexplained %d, drops %d, residual scale %.4f, twin spread %.3f px\n",
                 image.c_str(), s.floor_texture_edges, s.floor_contacts, s.undecided, s.elevated,
                 s.unexplained, s.drops, static_cast<double>(s.noise_scale),
                 static_cast<double>(s.twin_spread_px));
  }
}

}  // namespace

void add_scan_command(CLI::App &app) {
  auto *command = app.add_subcommand("scan", "print the local scan of one omnidirectional image as CSV");
  auto options = std::make_shared<ScanOptions>();
  command->add_option("IMAGE", options->image, "8-bit image of the configured camera size")->required();
  command->add_option("--config", options->config, "YAML configuration (camera, vision, stereo)");
  command->add_flag("--quiet", options->quiet, "no summary on stderr");
  command->add_flag("--free", options->free,
                    "print how far the floor was seen to be free per column instead "
                    "(azimuth_deg,free_range_m,drop_range_m,drop_lower_range_m; nan where unknown)");
  command->callback([options] {
    const io::Config config = options->config.empty() ? io::Config{} : io::load_config(options->config);
    const cv::Mat image = io::read_camera_image(options->image, config.scan.camera);
    stereo::ScanReconstructor reconstructor(config.scan);
    const stereo::LocalScan scan = reconstructor.reconstruct(image);
    if (options->free) {
      if (scan.free_range_m.empty()) throw std::runtime_error("--free needs stereo.boundary: floor_boundary");
      print_free_csv(scan, config.scan.camera);
    } else {
      print_csv(scan);
    }
    if (!options->quiet) print_summary(options->image, scan);
  });
}

}  // namespace omnislam::app
