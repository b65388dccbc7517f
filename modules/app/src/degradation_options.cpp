#include "degradation_options.hpp"

#include <stdexcept>

namespace omnislam::app {

CLI::Validator factor_list_validator() {
  return CLI::Validator(
      [](std::string &list) {
        degrade::DegradationConfig scratch;
        return degrade::apply_factor_list(list, scratch);
      },
      "FACTORS", "degradation factor list");
}

degrade::DegradationConfig degradation_for(degrade::DegradationConfig parameters,
                                           const std::string &factor_list,
                                           std::optional<std::uint64_t> seed) {
  if (const std::string error = degrade::apply_factor_list(factor_list, parameters); !error.empty()) {
    throw std::invalid_argument(error);
  }
  if (seed) parameters.seed = *seed;
  return parameters;
}

}  // namespace omnislam::app
