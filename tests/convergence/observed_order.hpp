#pragma once
// The observed order of convergence from errors on meshes refined by halving, for the convergence tests.
#include <cmath>
#include <cstddef>
#include <vector>

namespace chainsim::test {

/// The order fitted by least squares to errors on meshes halved one after the other (the slope of
/// log2 |error| against the number of halvings, negated).
inline double fitted_order(const std::vector<double>& errors) {
  const double n = static_cast<double>(errors.size()), mean_k = (n - 1) / 2;
  double mean_e = 0, cov = 0, var = 0;
  for (double e : errors) mean_e += std::log(std::abs(e)) / n;
  for (std::size_t k = 0; k < errors.size(); ++k) {
    const double dk = static_cast<double>(k) - mean_k;
    cov += dk * (std::log(std::abs(errors[k])) - mean_e);
    var += dk * dk;
  }
  return -cov / var / std::log(2.0);
}

}  // namespace chainsim::test
