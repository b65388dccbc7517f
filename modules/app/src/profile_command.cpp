#include "profile_command.hpp"

#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "omnislam/pipeline/profiler.hpp"

namespace omnislam::app {
namespace {

// Thesis fig. 8.21 (2008, per image): shares of the total time, grouped as the thesis
// grouped its steps, with the stages of this implementation that do the same work.
struct ThesisGroup {
  const char *thesis_step;
  double thesis_share;
  std::vector<std::string> stages;
};
const std::array<ThesisGroup, 6> kThesis = {{{"read+unwarp+write", 0.29, {"read", "unwarp"}},
                                             {"Canny", 0.31, {"canny"}},
                                             {"filter+SAD", 0.09, {"edges"}},
                                             {"DP", 0.13, {"match"}},
                                             {"local map", 0.00, {"triangulation"}},
                                             {"TrICP + global map update", 0.18, {"slam"}}}};

std::map<std::string, std::vector<double>> read_columns(const std::string &file,
                                                        std::vector<std::string> &order) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot open the file");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(file + ": empty");
  std::vector<std::string> header;
  std::stringstream names(line);
  for (std::string name; std::getline(names, name, ',');) header.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  for (int number = 2; std::getline(in, line); ++number) {
    std::stringstream cells(line);
    std::size_t i = 0;
    for (std::string cell; std::getline(cells, cell, ',') && i < header.size(); ++i) {
      try {
        columns[header[i]].push_back(std::stod(cell));
      } catch (const std::exception &) {
        throw std::runtime_error(file + ":" + std::to_string(number) + ": '" + cell + "' is not a number");
      }
    }
  }
  order = header;
  return columns;
}

void print_profile(const std::string &file) {
  std::vector<std::string> order;
  auto columns = read_columns(file, order);
  std::map<std::string, pipeline::DurationStats> stages;
  double total_ms = 0.0;
  for (std::string_view stage : pipeline::kStages) {
    const std::string column = std::string(stage) + "_ms";
    if (!columns.contains(column)) throw std::runtime_error(file + ": no column " + column);
    stages[std::string(stage)] = pipeline::summarize(columns[column]);
    total_ms += stages[std::string(stage)].mean_ms;
  }
  std::printf("%s: %zu frames\n\n%-16s %9s %9s %9s %9s %7s\n", file.c_str(), columns["read_ms"].size(),
              "stage", "mean_ms", "p50_ms", "p99_ms", "max_ms", "share");
  for (std::string_view name : pipeline::kStages) {
    const pipeline::DurationStats &s = stages[std::string(name)];
    std::printf("%-16s %9.3f %9.3f %9.3f %9.3f %6.1f%%\n", std::string(name).c_str(), s.mean_ms, s.p50_ms,
                s.p99_ms, s.max_ms, total_ms > 0 ? 100.0 * s.mean_ms / total_ms : 0.0);
  }
  std::printf("%-16s %9.3f\n\n%-28s %8s %8s  (thesis fig. 8.21, 2008)\n", "total", total_ms, "step", "ours",
              "thesis");
  for (const ThesisGroup &group : kThesis) {
    double ms = 0.0;
    for (const std::string &stage : group.stages) ms += stages[stage].mean_ms;
    std::printf("%-28s %7.1f%% %7.0f%%\n", group.thesis_step, total_ms > 0 ? 100.0 * ms / total_ms : 0.0,
                100.0 * group.thesis_share);
  }
  if (columns.contains("latency_ms")) {
    std::printf("\n%-16s %9s %9s %9s %9s %9s\n", "queue / latency", "mean_ms", "p50_ms", "p99_ms", "max_ms",
                "depth_max");
    for (std::string_view queue : pipeline::kQueues) {
      const std::string q(queue);
      const auto s = pipeline::summarize(columns["wait_" + q + "_ms"]);
      const auto depth = pipeline::summarize(columns["depth_" + q]);
      std::printf("%-16s %9.3f %9.3f %9.3f %9.3f %9.0f\n", ("wait " + q).c_str(), s.mean_ms, s.p50_ms,
                  s.p99_ms, s.max_ms, depth.max_ms);
    }
    const auto latency = pipeline::summarize(columns["latency_ms"]);
    std::printf("%-16s %9.3f %9.3f %9.3f %9.3f\n", "capture->pose", latency.mean_ms, latency.p50_ms,
                latency.p99_ms, latency.max_ms);
    double dropped = 0.0;
    for (double d : columns["dropped_before"]) dropped += d;
    std::printf("dropped frames: %.0f\n", dropped);
  }
}

}  // namespace

void add_profile_command(CLI::App &app) {
  auto *command = app.add_subcommand("profile", "per-stage profile of a run beside the thesis's shares");
  auto file = std::make_shared<std::string>();
  command->add_option("profile_csv", *file, "a run's profile.csv")->required();
  command->callback([file] { print_profile(*file); });
}

}  // namespace omnislam::app
