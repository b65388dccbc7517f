// bench_frontend IMAGE_OR_DATASET [--reps N] [--config FILE] [--no-sgbm] [--degrade LIST]
//                [--degrade-seed N]: times each stage of the one-image reconstruction (unwarp,
// Canny, edge selection, matching, triangulation) on one thread, and OpenCV StereoSGBM on the
// same panoramas (unless --no-sgbm); on a dataset also reports the accuracy of both against
// floorplan.csv (the metrics of tests/stereo/test_scan_accuracy.cpp). --degrade applies the
// degradation stage once at load (frame n gets frame number n, as replay --degrade does), with
// the config file's degradation parameters.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "omnislam/degrade/degradation.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/io/image_file.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"
#include "scan_truth.hpp"
#include "sgbm_matcher.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using omnislam::stereo::LocalScan;
using omnislam::stereo::ScanConfig;
using omnislam::stereo::ScanReconstructor;

double ms_since(Clock::time_point &start) {
  const Clock::time_point now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

struct Samples {
  const char *name;
  std::vector<double> ms;
  [[nodiscard]] double quantile(double q) const {
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    return sorted.empty() ? 0.0
                          : sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
  }
  void print() const {
    std::printf("  %-34s %8.3f %8.3f %8.3f\n", name, quantile(0.5), quantile(0.99), quantile(1.0));
  }
};

struct Frames {
  std::vector<cv::Mat> images;
  std::vector<omnislam::test::Pose2> poses;  // empty without ground truth
  std::vector<omnislam::io::FloorplanSegment> segments;
  ScanConfig config;
};

struct Options {
  int reps = 30;
  std::string config_file;
  bool with_sgbm = true;
  std::string degrade = "none";
  std::optional<std::uint64_t> degrade_seed;
};

void degrade(const Options &options, omnislam::degrade::DegradationConfig parameters,
             std::vector<cv::Mat> &images) {
  if (const std::string error = omnislam::degrade::apply_factor_list(options.degrade, parameters);
      !error.empty())
    throw std::invalid_argument("--degrade: " + error);
  if (options.degrade_seed) parameters.seed = *options.degrade_seed;
  if (images.empty() || omnislam::degrade::enabled_factors(parameters) == "none") return;
  const omnislam::degrade::Degrader degrader(parameters, images.front().size());
  for (std::size_t i = 0; i < images.size(); ++i) {
    omnislam::degrade::Degraded result = degrader.apply(images[i], static_cast<int>(i) + 1);
    if (!result.ok()) throw std::runtime_error("frame " + std::to_string(i + 1) + ": " + result.error);
    images[i] = result.image;
  }
}

Frames load(const std::filesystem::path &input, const Options &options) {
  Frames frames;
  omnislam::degrade::DegradationConfig degradation;
  if (!options.config_file.empty()) {
    const omnislam::io::Config config = omnislam::io::load_config(options.config_file);
    frames.config = config.scan;
    degradation = config.degradation;
  }
  if (std::filesystem::is_directory(input)) {
    omnislam::test::TruthDataset data = omnislam::test::load_truth_dataset(input);
    frames.images = std::move(data.images);
    frames.poses = std::move(data.poses);
    frames.segments = std::move(data.segments);
    frames.config.camera = data.info.camera;
    frames.config.camera_height_m = data.info.camera_height_m;
  } else {
    frames.images.push_back(omnislam::io::read_camera_image(input, frames.config.camera));
  }
  degrade(options, degradation, frames.images);
  return frames;
}

void print_accuracy(const char *name, const Frames &frames, ScanConfig config) {
  ScanReconstructor reconstructor(config);
  omnislam::test::ScanAccuracy accuracy;
  for (std::size_t i = 0; i < frames.images.size(); ++i) {
    accuracy.add(reconstructor.reconstruct(frames.images[i]), frames.poses[i], frames.segments);
  }
  std::printf("  %-28s %s\n", name, accuracy.summary().c_str());
}

}  // namespace

int main(int argc, char **argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: bench_frontend IMAGE_OR_DATASET [--reps N] [--config FILE] [--no-sgbm] "
                 "[--degrade LIST] [--degrade-seed N]\n");
    return 2;
  }
  Options options;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--no-sgbm") options.with_sgbm = false;
    if (i + 1 >= argc) continue;
    if (arg == "--reps") options.reps = std::max(1, std::atoi(argv[i + 1]));
    if (arg == "--config") options.config_file = argv[i + 1];
    if (arg == "--degrade") options.degrade = argv[i + 1];
    if (arg == "--degrade-seed") options.degrade_seed = std::strtoull(argv[i + 1], nullptr, 10);
  }
  const int reps = options.reps;
  const bool with_sgbm = options.with_sgbm;
  try {
    cv::setNumThreads(1);
    const Frames frames = load(argv[1], options);
    ScanReconstructor reconstructor(frames.config);
    omnislam::bench::SgbmMatcher sgbm(reconstructor.disparity_limits());
    Samples unwarp{"unwarp (2 lobes)", {}}, canny{"Canny + fragments (2 lobes)", {}};
    Samples select{"edge selection (2 lobes)", {}},
        dp{frames.config.stereo.boundary == omnislam::stereo::BoundaryMethod::kNearestEdge
               ? "DP matching"
               : "floor boundary search",
           {}},
        triangulate{"triangulation + filter", {}};
    Samples total{"total (one image -> scan)", {}};
    Samples sgbm_match{"StereoSGBM (transpose, pad, match)", {}},
        sgbm_scan{"SGBM triangulation + filter", {}};
    LocalScan scan, sgbm_scan_out;
    std::vector<omnislam::stereo::RowMatch> sgbm_matches;
    omnislam::test::ScanAccuracy sgbm_accuracy;
    for (int rep = -1; rep < reps; ++rep) {  // rep -1 warms caches and buffers
      for (std::size_t i = 0; i < frames.images.size(); ++i) {
        Clock::time_point start = Clock::now();
        const Clock::time_point first = start;
        reconstructor.unwarp(frames.images[i]);
        const double t_unwarp = ms_since(start);
        reconstructor.detect_edges();
        const double t_canny = ms_since(start);
        reconstructor.select_edges();
        const double t_select = ms_since(start);
        reconstructor.match();
        const double t_dp = ms_since(start);
        scan.points.clear();
        scan.stats = {};
        reconstructor.triangulate(scan);
        const double t_tri = ms_since(start);
        const double t_total = std::chrono::duration<double, std::milli>(start - first).count();
        double t_sgbm = 0.0, t_sgbm_scan = 0.0;
        if (with_sgbm) {
          sgbm.match(reconstructor, sgbm_matches);
          t_sgbm = ms_since(start);
          sgbm_scan_out.stats = {};
          reconstructor.build_scan(sgbm_matches, sgbm_scan_out);
          t_sgbm_scan = ms_since(start);
        }
        if (rep < 0) {
          if (with_sgbm && !frames.poses.empty())
            sgbm_accuracy.add(sgbm_scan_out, frames.poses[i], frames.segments);
          continue;
        }
        unwarp.ms.push_back(t_unwarp);
        canny.ms.push_back(t_canny);
        select.ms.push_back(t_select);
        dp.ms.push_back(t_dp);
        triangulate.ms.push_back(t_tri);
        total.ms.push_back(t_total);
        sgbm_match.ms.push_back(t_sgbm);
        sgbm_scan.ms.push_back(t_sgbm_scan);
      }
    }
    const auto &limits = reconstructor.disparity_limits();
    std::printf("bench_frontend %s: %zu frame(s) x %d repetitions, one thread, degradation: %s\n", argv[1],
                frames.images.size(), reps, options.degrade.c_str());
    std::printf(
        "disparity band from the mirror model: %.2f..%.2f px over all inner rows "
        "(camera %.2f m up, search %.2f..%.2f m)\n",
        static_cast<double>(limits.min_px), static_cast<double>(limits.max_px), frames.config.camera_height_m,
        frames.config.stereo.min_range_m, frames.config.stereo.max_range_m);
    std::printf("  %-34s %8s %8s %8s\n", "stage [ms]", "median", "p99", "max");
    for (const Samples *s : {&unwarp, &canny, &select, &dp, &triangulate, &total}) s->print();
    if (with_sgbm) {
      std::printf("StereoSGBM on the same panoramas (min disparity %d, %d disparities, block %d):\n",
                  sgbm.min_disparity(), sgbm.num_disparities(), 5);
      sgbm_match.print();
      sgbm_scan.print();
      std::printf("  %-34s %8.3f\n", "SGBM pipeline median (total - DP + SGBM)",
                  total.quantile(0.5) - dp.quantile(0.5) + sgbm_match.quantile(0.5));
    }
    if (!frames.poses.empty()) {
      std::printf("accuracy against floorplan.csv:\n");
      print_accuracy("floor boundary (default)", frames, frames.config);
      ScanConfig variant = frames.config;
      variant.stereo.floor.floor_plane_range = false;
      print_accuracy("floor boundary, stereo range", frames, variant);
      variant = frames.config;
      variant.stereo.boundary = omnislam::stereo::BoundaryMethod::kNearestEdge;
      print_accuracy("nearest edge + DP (thesis)", frames, variant);
      variant.stereo.subpixel = omnislam::stereo::SubpixelMethod::kCostCurve;
      print_accuracy("DP, cost-curve sub-pixel", frames, variant);
      variant.stereo.subpixel = omnislam::stereo::SubpixelMethod::kNone;
      print_accuracy("DP, integer rows", frames, variant);
      variant.stereo.triangulation = omnislam::stereo::TriangulationMethod::kTable;
      print_accuracy("DP, integer rows + LUT", frames, variant);
      if (with_sgbm) std::printf("  %-28s %s\n", "StereoSGBM", sgbm_accuracy.summary().c_str());
    }
  } catch (const std::exception &error) {
    std::fprintf(stderr, "bench_frontend: error: %s\n", error.what());
    return 1;
  }
  return 0;
}
