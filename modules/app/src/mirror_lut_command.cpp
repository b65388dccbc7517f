#include "mirror_lut_command.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>

#include "omnislam/io/lut_files.hpp"
#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/mirror/triangulation_table.hpp"

namespace omnislam::app {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

void print_summary(const mirror::MirrorModel &model, const mirror::TriangulationTable &table,
                   const std::filesystem::path &dir) {
  using mirror::Lobe;
  const int rows = table.rows();
  std::printf("wrote %s and %s (%d x %d, mm)\n", (dir / "rP.txt").c_str(), (dir / "zP.txt").c_str(), rows,
              rows);
  std::printf("valid entries: %zu of %d\n", table.valid_count(), rows * rows);
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const auto radii = model.radius_range(lobe);
    const auto thetas = model.theta_range(lobe);
    std::printf("%s lobe: radius %.0f..%.0f px, theta %.3f..%.3f deg from nadir\n",
                lobe == Lobe::kInner ? "inner" : "outer", radii.min_px, radii.max_px,
                thetas.min_rad * kDegPerRad, thetas.max_rad * kDegPerRad);
  }
  const auto sample = table.at(45, 60);
  if (sample) {
    std::printf("[45,60] (annex A1.3 example): r = %.3f mm, z = %.3f mm\n", sample->range_m * 1e3,
                sample->height_m * 1e3);
  }
}

}  // namespace

void add_mirror_lut_command(CLI::App &app) {
  auto *command = app.add_subcommand("mirror-lut", "write the triangulation table rP.txt / zP.txt");
  auto out_dir = std::make_shared<std::string>();
  command->add_option("--out", *out_dir, "output directory")->required();
  command->callback([out_dir] {
    const mirror::MirrorModel model;
    const mirror::TriangulationTable table(model);
    io::write_lut_files(*out_dir, table);
    print_summary(model, table, *out_dir);
  });
}

}  // namespace omnislam::app
