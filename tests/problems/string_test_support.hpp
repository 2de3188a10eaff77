#pragma once
// Shared set-ups for the string-solver tests (tests/problems, tests/convergence): a hanging chain,
// a closed loop, zero-crossing times of a scalar observable, and a rate table printer.
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/math/special_functions/bessel.hpp>

#include "mesh/discretize.hpp"
#include "solver/integrator.hpp"
#include "solver/string_model.hpp"

namespace chainsim::testing {

constexpr double kG = 9.81;

/// A chain of length `length` hanging from a fixed node 0 at the origin along −y, with `links`
/// links, density 1, lateral displacement x(s) = shape(σ) (σ = length − s: distance from the free
/// end), at rest. Gravity (0, −g); optional linear drag; Baumgarte time tau_b; the discretization
/// (StringModelOptions::elements: "links", or "quadratic" with an even number of links); the
/// factorisation of implicit methods' Newton systems (StringModelOptions::linear_solver).
inline std::unique_ptr<StringModel<2>> hanging_chain(int links, double length, const std::function<double(double)>& shape,
                                                     double tau_b, double drag = 0,
                                                     const std::string& elements = "links",
                                                     const std::string& linear_solver = "auto") {
  Chain<2> chain = Chain<2>::uniform(1.0, length, links, false);
  for (int i = 0; i <= links; ++i) {
    const double s = length * i / links;
    chain.positions().col(i) = Vec<2>(shape(length - s), -s);
  }
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  if (drag > 0) forces.push_back(std::make_unique<Drag<2>>(drag));
  std::vector<PrescribedNode<2>> fixed = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0.0, 0.0))}};
  StringModelOptions options;
  options.stabilization_time = tau_b;
  options.elements = elements;
  options.linear_solver = linear_solver;
  auto model = std::make_unique<StringModel<2>>(std::move(chain), std::move(forces), fixed, options);
  model->make_consistent(0.0);
  return model;
}

/// Times at which q(t, y) changes sign over [0, t_end], located on ARKODE's dense output by
/// bisection to ~1e-13 of the step. `stats`, if given, receives the integrator's counters.
inline std::vector<double> zero_crossings(OdeSystem& system, const Eigen::VectorXd& y0, const IntegratorOptions& options,
                                          double t_end, const std::function<double(const Eigen::VectorXd&)>& q,
                                          IntegratorStats* stats = nullptr) {
  Integrator integrator(system, 0.0, y0, options);
  std::vector<double> crossings;
  double t_prev = 0.0, q_prev = q(y0);
  while (integrator.time() < t_end) {
    integrator.advance(t_end, true);
    const double t = integrator.time(), q_now = q(integrator.state());
    if ((q_prev < 0) != (q_now < 0)) {
      double a = t_prev, b = t, qa = q_prev;
      for (int k = 0; k < 60 && b - a > 1e-14 * (1 + t); ++k) {
        const double m = 0.5 * (a + b), qm = q(integrator.interpolate(m));
        if ((qa < 0) == (qm < 0)) {
          a = m;
          qa = qm;
        } else {
          b = m;
        }
      }
      crossings.push_back(0.5 * (a + b));
    }
    t_prev = t;
    q_prev = q_now;
  }
  if (stats) *stats = integrator.stats();
  return crossings;
}

/// Least-squares slope of t_k against k: the mean spacing of the crossings (half a period).
inline double mean_spacing(const std::vector<double>& t) {
  const double n = static_cast<double>(t.size());
  double sk = 0, st = 0, skk = 0, skt = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double kk = static_cast<double>(k);
    sk += kk;
    st += t[k];
    skk += kk * kk;
    skt += kk * t[k];
  }
  return (n * skt - sk * st) / (n * skk - sk * sk);
}

/// A frequency measured on the hanging chain, with the integrator's counters.
struct ModeMeasurement {
  double omega = 0;  ///< measured (rad/s)
  double exact = 0;  ///< ½ j_{0,n} √(g/ℓ)
  int crossings = 0;
  IntegratorStats stats;
  double relative_error() const { return std::abs(omega - exact) / exact; }
};

/// Mode `mode` of a hanging chain of length 1 with `links` links (τ_b = 0.1 √(ℓ/g)), started at rest
/// on the mode shape J0(j_{0,n} √(σ/ℓ)) with lateral amplitude `amplitude`, run for `periods` periods:
/// the frequency from the zero crossings of the modal projection q(t) = Σ_i m_i u_i(t) φ_n(σ_i)
/// (u: lateral displacement), as the slope of a least-squares fit of the crossing times. 0 crossings
/// or 1: omega = 0.
inline ModeMeasurement measure_mode(int links, int mode, double periods, const IntegratorOptions& options,
                                    double amplitude, const std::string& elements = "links",
                                    const std::string& linear_solver = "auto") {
  const double length = 1.0;
  const double j = boost::math::cyl_bessel_j_zero(0.0, mode);
  ModeMeasurement out;
  out.exact = 0.5 * j * std::sqrt(kG / length);
  auto phi = [&](double sigma) { return boost::math::cyl_bessel_j(0, j * std::sqrt(std::max(sigma, 0.0) / length)); };
  auto model = hanging_chain(links, length, [&](double sigma) { return amplitude * length * phi(sigma); },
                             0.1 * std::sqrt(length / kG), 0.0, elements, linear_solver);
  const Chain<2>& chain = model->chain();
  // Weights of the modal projection on the free nodes (state order: node 1..n-1).
  Eigen::VectorXd w(chain.num_nodes() - 1);
  for (int i = 1; i < chain.num_nodes(); ++i) w[i - 1] = chain.mass(i) * phi(length - chain.node_coordinate(i));
  auto q = [&](const Eigen::VectorXd& y) {
    double sum = 0;
    for (int k = 0; k < w.size(); ++k) sum += w[k] * y[2 * k];
    return sum;
  };
  const double period = 2 * kPi / out.exact;
  const auto crossings = zero_crossings(*model, model->state_from_chain(), options, periods * period, q, &out.stats);
  out.crossings = static_cast<int>(crossings.size());
  if (crossings.size() >= 2) out.omega = kPi / mean_spacing(crossings);
  return out;
}

/// Observed orders log2(e_k / e_{k+1}) for halved mesh sizes, printed as a table.
inline std::vector<double> rate_table(const std::string& title, const std::string& column, const std::vector<int>& n,
                                      const std::vector<double>& error) {
  std::vector<double> rates;
  std::printf("\n%s\n  %8s  %14s  %6s\n", title.c_str(), column.c_str(), "error", "rate");
  for (std::size_t k = 0; k < n.size(); ++k) {
    if (k == 0) {
      std::printf("  %8d  %14.6e  %6s\n", n[k], error[k], "-");
      continue;
    }
    const double rate = std::log(error[k - 1] / error[k]) / std::log(static_cast<double>(n[k]) / n[k - 1]);
    rates.push_back(rate);
    std::printf("  %8d  %14.6e  %6.3f\n", n[k], error[k], rate);
  }
  std::fflush(stdout);
  return rates;
}

}  // namespace chainsim::testing
