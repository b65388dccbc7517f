#pragma once

#include <ceres/cost_function.h>

#include <functional>
#include <utility>
#include <vector>

/// @file
/// A Ceres cost function differentiated by central differences with a fixed step per
/// parameter. Ceres's own numeric differentiation steps relative to the value, so on a
/// parameter near zero (a small rotation, a tilt) the step shrinks to ~1e-8 and the traced
/// model's own convergence noise (~1e-9 px) swamps the difference.

namespace omnislam::calib::detail {

class FiniteDifferenceCost : public ceres::CostFunction {
 public:
  /// Fills `residuals` from the parameter blocks; false where the model has no value.
  using Residual = std::function<bool(const double *const *parameters, double *residuals)>;

  /// `steps[b][j]` is the step of parameter j of block b (its size is the block's size).
  FiniteDifferenceCost(int residuals, std::vector<std::vector<double>> steps, Residual residual)
      : steps_(std::move(steps)), residual_(std::move(residual)) {
    set_num_residuals(residuals);
    for (const std::vector<double> &block : steps_)
      mutable_parameter_block_sizes()->push_back(int(block.size()));
  }

  bool Evaluate(const double *const *parameters, double *residuals, double **jacobians) const override {
    if (!residual_(parameters, residuals)) return false;
    if (jacobians == nullptr) return true;
    std::vector<std::vector<double>> values(steps_.size());
    std::vector<const double *> pointers(steps_.size());
    for (std::size_t b = 0; b < steps_.size(); ++b) {
      values[b].assign(parameters[b], parameters[b] + steps_[b].size());
      pointers[b] = values[b].data();
    }
    const auto n = static_cast<std::size_t>(num_residuals());
    std::vector<double> plus(n), minus(n);
    for (std::size_t b = 0; b < steps_.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      const std::size_t size = steps_[b].size();
      for (std::size_t j = 0; j < size; ++j) {
        const double step = steps_[b][j];
        values[b][j] = parameters[b][j] + step;
        const bool ok_plus = residual_(pointers.data(), plus.data());
        values[b][j] = parameters[b][j] - step;
        const bool ok_minus = residual_(pointers.data(), minus.data());
        values[b][j] = parameters[b][j];
        if (!ok_plus || !ok_minus) return false;
        for (std::size_t r = 0; r < n; ++r) jacobians[b][r * size + j] = (plus[r] - minus[r]) / (2.0 * step);
      }
    }
    return true;
  }

 private:
  std::vector<std::vector<double>> steps_;
  Residual residual_;
};

}  // namespace omnislam::calib::detail
