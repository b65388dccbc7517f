#include "degrade_command.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "degradation_options.hpp"
#include "omnislam/degrade/degradation.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/dataset.hpp"
#include "omnislam/io/image_file.hpp"

namespace omnislam::app {
namespace {

namespace fs = std::filesystem;

struct DegradeOptions {
  std::string dataset;
  std::string out_dir;
  std::string factors = "all";
  std::string config_file;
  std::uint64_t seed = 1;
};

// The frame images' paths relative to the dataset directory. They are rewritten as PNG
// under the same names, so they must lie inside the dataset and be named *.png.
std::set<fs::path> frame_images(const io::DatasetInfo &info) {
  std::set<fs::path> images;
  for (int frame = 1; frame <= info.frames; ++frame) {
    const fs::path relative =
        info.image(frame).lexically_normal().lexically_relative(info.dir.lexically_normal());
    if (relative.empty() || relative.is_absolute() || *relative.begin() == "..") {
      throw std::runtime_error(info.image(frame).string() + ": image outside the dataset directory " +
                               info.dir.string());
    }
    if (relative.extension() != ".png") {
      throw std::runtime_error(info.image(frame).string() + ": only .png frame images can be rewritten");
    }
    images.insert(relative);
  }
  return images;
}

// Copies every other regular file of the dataset (dataset.yaml, ground truth, odometry,
// floor plan, anything else) unchanged; returns how many.
int copy_other_files(const fs::path &in_dir, const fs::path &out_dir, const std::set<fs::path> &images) {
  int copied = 0;
  for (auto it = fs::recursive_directory_iterator(in_dir); it != fs::recursive_directory_iterator(); ++it) {
    if (it->is_directory() && fs::equivalent(it->path(), out_dir)) {
      it.disable_recursion_pending();  // --out inside the dataset: do not copy the copy
      continue;
    }
    if (!it->is_regular_file()) continue;
    const fs::path relative = it->path().lexically_relative(in_dir);
    if (images.contains(relative.lexically_normal())) continue;
    fs::create_directories((out_dir / relative).parent_path());
    fs::copy_file(it->path(), out_dir / relative, fs::copy_options::overwrite_existing);
    ++copied;
  }
  return copied;
}

void run_degrade(const DegradeOptions &options, std::optional<std::uint64_t> seed) {
  const io::DatasetInfo info = io::read_dataset_info(options.dataset);
  const io::Config config = options.config_file.empty() ? io::Config{} : io::load_config(options.config_file);
  const degrade::DegradationConfig degradation = degradation_for(config.degradation, options.factors, seed);
  const std::set<fs::path> images = frame_images(info);

  const fs::path out_dir = options.out_dir;
  std::error_code error;
  fs::create_directories(out_dir, error);
  if (error || !fs::is_directory(out_dir)) {
    throw std::runtime_error(out_dir.string() + ": cannot create the output directory");
  }
  if (fs::equivalent(info.dir, out_dir)) {
    throw std::runtime_error(out_dir.string() + ": --out is the dataset itself; choose another directory");
  }
  const int copied = copy_other_files(info.dir, out_dir, images);

  const degrade::Degrader degrader(degradation, {info.camera.image_width_px, info.camera.image_height_px});
  for (int frame = 1; frame <= info.frames; ++frame) {
    const fs::path file = info.image(frame);
    const degrade::Degraded degraded = degrader.apply(io::read_camera_image(file, info.camera), frame);
    if (!degraded.ok()) throw std::runtime_error(file.string() + ": " + degraded.error);
    const fs::path target = out_dir / file.lexically_normal().lexically_relative(info.dir.lexically_normal());
    fs::create_directories(target.parent_path());
    io::write_png_image(target, degraded.image);
  }
  std::printf("%s: %d frames degraded (%s; seed %llu) into %s, %d other files copied\n", info.name.c_str(),
              info.frames, degrade::enabled_factors(degradation).c_str(),
              static_cast<unsigned long long>(degradation.seed), out_dir.string().c_str(), copied);
}

}  // namespace

void add_degrade_command(CLI::App &app) {
  auto *command = app.add_subcommand("degrade", "write a copy of a dataset with realistic camera images");
  auto options = std::make_shared<DegradeOptions>();
  command->add_option("dataset", options->dataset, "dataset directory (with dataset.yaml)")->required();
  command->add_option("--out", options->out_dir, "output directory (the degraded dataset)")->required();
  command
      ->add_option("--factors", options->factors,
                   "all, none, or a comma-separated list of exposure, vignetting, dust, blur, noise, jpeg")
      ->check(factor_list_validator())
      ->capture_default_str();
  auto *seed =
      command->add_option("--seed", options->seed, "seed of the degradation (default: the config's, 1)");
  command->add_option("--config", options->config_file, "YAML configuration (its degradation: section)");
  command->callback([options, seed] {
    run_degrade(*options, seed->count() > 0 ? std::optional(options->seed) : std::nullopt);
  });
}

}  // namespace omnislam::app
