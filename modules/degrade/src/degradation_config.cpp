#include <algorithm>
#include <array>
#include <cstddef>

#include "omnislam/degrade/degradation_config.hpp"

namespace omnislam::degrade {
namespace {

// The enabled switches in kFactorNames order.
std::array<bool *, kFactorNames.size()> switches(DegradationConfig &config) {
  return {&config.exposure.enabled, &config.vignetting.enabled, &config.dust.enabled,
          &config.blur.enabled,     &config.noise.enabled,      &config.jpeg.enabled};
}

std::string_view trim(std::string_view text) {
  constexpr std::string_view kBlank = " \t";
  const std::size_t first = text.find_first_not_of(kBlank);
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(kBlank) - first + 1);
}

std::string valid_names() {
  std::string names = "all, none, or a comma-separated list of";
  for (std::size_t i = 0; i < kFactorNames.size(); ++i) {
    names.append(i == 0 ? " " : ", ").append(kFactorNames[i]);
  }
  return names;
}

}  // namespace

std::string apply_factor_list(std::string_view list, DegradationConfig &config) {
  std::array<bool, kFactorNames.size()> listed{};
  const std::string_view whole = trim(list);
  if (whole == "all") {
    listed.fill(true);
  } else if (whole != "none") {
    for (std::size_t start = 0; start <= whole.size();) {
      const std::size_t end = std::min(whole.find(',', start), whole.size());
      const std::string_view name = trim(whole.substr(start, end - start));
      const auto *found = std::find(kFactorNames.begin(), kFactorNames.end(), name);
      if (name.empty()) {
        return std::string("empty degradation factor in '").append(list).append("' (valid: ") +
               valid_names() + ")";
      }
      if (found == kFactorNames.end()) {
        return std::string("unknown degradation factor '").append(name).append("' (valid: ") + valid_names() +
               ")";
      }
      listed[static_cast<std::size_t>(found - kFactorNames.begin())] = true;
      start = end + 1;
    }
  }
  const auto enabled = switches(config);
  for (std::size_t i = 0; i < enabled.size(); ++i) *enabled[i] = *enabled[i] && listed[i];
  return {};
}

std::string enabled_factors(const DegradationConfig &config) {
  DegradationConfig copy = config;
  const auto enabled = switches(copy);
  std::string names;
  for (std::size_t i = 0; i < enabled.size(); ++i) {
    if (*enabled[i]) names.append(names.empty() ? "" : ",").append(kFactorNames[i]);
  }
  return names.empty() ? "none" : names;
}

}  // namespace omnislam::degrade
