#pragma once
/// @file edge_case.hpp
/// The chain sliding off a smooth table over a sharp edge (docs/model.md §8) on the string solver,
/// against its exact solution (cases/reduced/exact_solutions.hpp, exact::edge_*): `chainsim compare
/// edge`. A chain of length ℓ lies straight on the table (y = 0, x < 0), x0 ℓ of it hanging vertically
/// over the edge at the origin, released at rest; the edge's dissipation f = chain.dissipation. The run
/// stops at the lift-off event (or at the safety stop t_max_over_t0 t0).
#include <nlohmann/json.hpp>

#include "cases/canonical/canonical_string.hpp"

namespace chainsim {

struct EdgeCaseSetup {
  ChainParameters chain;        ///< ℓ, λ, g and the edge's f
  int nodes = 101;              ///< nodes of the string, 3 <= nodes <= 200001
  double x0 = 0.2;              ///< the hanging fraction at release, 0 < x0 < 1
  double t_max_over_t0 = 50.0;  ///< safety stop (the chain lifts off the edge well before)
  IntegratorOptions integrator = StringCaseSetup::default_integrator();
  /// InputError naming the option (--nodes, --x0, --f, ...), its value and the allowed range.
  void validate() const;
};

/// The string run and its comparison with exact::edge_*. Summary keys (besides the string run's,
/// among them energy_residual, momentum_residual and events):
///   problem = "edge", nodes, f, x0 (hanging fraction),
///   t_stop_over_t0, t_stop_over_t0_exact, rel_err_t_stop   the stop (lift-off) time in units of t0,
///   t_lift_off, t_lift_off_exact, abs_err_t_lift_off       the lift-off event's time (s),
///   x_lift_off, x_lift_off_exact, abs_err_x_lift_off       the hanging length there (m),
///   max_abs_err_x        max over the steps of |x − exact::edge_x| (m),
///   max_abs_err_tension  max over the steps of |τ⁻ − λ (ℓ − x) ẍ| at the edge (N), with x, ẍ exact,
///   max_rel_err_tension  the same over λ g ℓ.
/// With no lift-off (a failed run, or the safety stop) the lift-off keys of the string are null.
struct EdgeComparison {
  RunSummary run;
  CsvTable exact{std::vector<std::string>{"t", "x", "x_dot", "tension_edge"}};  ///< at the string's step times
  nlohmann::json summary;
};
EdgeComparison compare_edge_with_exact(const EdgeCaseSetup& setup);

}  // namespace chainsim
