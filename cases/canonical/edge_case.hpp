#pragma once
/// @file edge_case.hpp
/// The canonical problems of a chain over a point fixed in space (docs/model.md §8) on the string solver,
/// against their exact solutions (cases/reduced/exact_solutions.hpp): `chainsim compare edge` and
/// `chainsim compare peg`. Both run the same string with one edge front (shocks/edge_front.hpp) at the
/// origin, released at rest, the kink's dissipation f = chain.dissipation, and stop at the lift-off
/// event (or at the safety stop t_max_over_t0 t0):
///   - edge: a chain of length ℓ lies straight on a smooth table (y = 0, x < 0), x0 ℓ of it hanging
///     vertically over the sharp edge (exact::edge_*);
///   - peg: the heavy Atwood chain, x0 ℓ of it hanging straight down on one side of a sharp peg (radius
///     zero), (1 − x0) ℓ on the other (exact::peg_*).
#include <nlohmann/json.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "cases/canonical/contact_compare.hpp"

namespace chainsim {

/// Which chain over a point: the chain sliding off a table over its edge, or the chain over a peg.
enum class PointContactProblem { kEdge, kPeg };

struct EdgeCaseSetup {
  ChainParameters chain;        ///< ℓ, λ, g and the kink's f
  PointContactProblem problem = PointContactProblem::kEdge;
  int nodes = 101;              ///< nodes of the string, 3 <= nodes <= 200001
  /// edge: the hanging fraction at release, 0 < x0 < 1; peg: the longer side's fraction, 0.5 < x0 < 1.
  double x0 = 0.2;
  double t_max_over_t0 = 50.0;  ///< safety stop (the chain lifts off well before)
  /// edge: the table is a contact surface that ends at the edge (its nodes held by their contact
  /// forces, docs/model.md §10) rather than the edge's known load (table = "before", §8).
  bool table_surface = false;
  IntegratorOptions integrator = StringCaseSetup::default_integrator();
  /// x0's default for a problem (edge 0.2, peg 0.6).
  static double default_x0(PointContactProblem problem) { return problem == PointContactProblem::kPeg ? 0.6 : 0.2; }
  /// InputError naming the option (--nodes, --x0, --f, ...), its value and the allowed range.
  void validate() const;
};
using PegCaseSetup = EdgeCaseSetup;  ///< with problem = PointContactProblem::kPeg

/// The string run and its comparison with the exact solution. Summary keys (besides the string run's,
/// among them energy_residual, momentum_residual and events): those of every comparison
/// (exact_comparison_summary, contact_compare.hpp: problem = "edge" | "peg", nodes, the lift-off
/// event's t and x against the exact ones, max_abs_err_x; x is the edge's hanging length, the peg's
/// longer side), and
///   f, x0 (edge: hanging fraction; peg: the longer side's),
///   t_stop_over_t0, t_stop_over_t0_exact, rel_err_t_stop   the stop (the lift-off) time in units of t0,
///   max_abs_err_tension  max over the steps of |τ⁻ − exact τ⁻| (N): the tension before the point, with x, ẍ exact
///                        (edge: the table part's pull λ (ℓ − x) ẍ; peg: the rising side's λ (ℓ − x)(g + ẍ)),
///   max_rel_err_tension  the same over λ g ℓ,
///   max_abs_err_tension_plus  the same for τ⁺ = τ⁻ + [τ] after the point (N),
///   max_abs_err_reaction      max over the steps of |F0 − exact F0| (N), the point's reaction,
///   dissipated, dissipated_exact, abs_err_dissipated   the kink's dissipation ∫ D dt up to the stop (J):
///                        −W_shocks of the run, and the exact energy balance's loss at the exact stop,
///   peg only: t_end_at_peg_exact   when the shorter end would reach the peg (s; after the lift-off for f < 1).
/// With no lift-off (a failed run, or the safety stop) the lift-off keys of the string are null.
/// exact: at the string's step times, t, x, x_dot, the tension before the point (edge: tension_edge,
/// peg: tension_minus), tension_plus, reaction_x, reaction_y (the exact solution's).
using EdgeComparison = ExactComparison;
using PegComparison = EdgeComparison;

/// setup.problem must be kEdge (the chain sliding off a table over an edge).
EdgeComparison compare_edge_with_exact(const EdgeCaseSetup& setup);
/// setup.problem must be kPeg (the heavy Atwood chain over a sharp peg).
PegComparison compare_peg_with_exact(const PegCaseSetup& setup);

}  // namespace chainsim
