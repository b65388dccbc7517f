#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "omnislam/degrade/degradation_config.hpp"

// The factor-list and seed flags shared by `omnislam degrade` and `omnislam replay --degrade`.
namespace omnislam::app {

/// A CLI11 check of a factor list ("all", "none", "noise,blur", ...): the error names the
/// bad entry and the valid names.
[[nodiscard]] CLI::Validator factor_list_validator();

/// `parameters` (the config file's `degradation:` section) restricted to `factor_list`,
/// with `seed` instead of the configured one when given. Throws std::invalid_argument on
/// a bad list (the validator catches that earlier).
[[nodiscard]] degrade::DegradationConfig degradation_for(degrade::DegradationConfig parameters,
                                                         const std::string &factor_list,
                                                         std::optional<std::uint64_t> seed);

}  // namespace omnislam::app
