#pragma once
/// @file pulley_case.hpp
/// The heavy Atwood chain over a smooth pulley on the string solver against its exact solution
/// (docs/model.md §10, cases/reduced/exact_solutions.hpp exact::pulley_*): `chainsim compare pulley`.
/// A chain of length ℓ hangs over a fixed smooth pulley of radius R at the origin (a circle: the contact
/// module, solver/contact_module.hpp), x2 = ℓ_free/2 − u0 on the left (the shorter side), x1 = ℓ_free/2 +
/// u0 on the right, the half circle πR between (ℓ_free = ℓ − πR), released at rest. The pulley holds the
/// string link by link (Obstacle::arc_links: links along the arc, docs/model.md §10). It runs to just past
/// the exact lift-off, 1.005 t* (or the safety stop t_max_over_t0 t0): u = u0 cosh(√(2g/ℓ) t), the tensions
/// λ x2 (g + ẍ) and λ x1 (g − ẍ) where the sides meet the pulley, and the lift-off where the shorter
/// side's falls to λ ẋ².
#include <array>

#include "cases/canonical/canonical_string.hpp"
#include "cases/canonical/contact_compare.hpp"

namespace chainsim {

struct PulleyCaseSetup {
  ChainParameters chain;        ///< ℓ, λ, g (its dissipation is not used: the pulley is smooth)
  int nodes = 101;              ///< nodes of the string, 3 <= nodes <= 200001
  double u0 = 0.05;             ///< the offset at release (m): 0 < u0 < ℓ_free/2 (the shorter side hangs)
  double radius = 0.1;          ///< the pulley's radius R (m): 0 < πR < ℓ
  double t_max_over_t0 = 50.0;  ///< safety stop (the chain lifts off well before)
  IntegratorOptions integrator = StringCaseSetup::default_integrator();
  /// InputError naming the option (--nodes, --u0, --R, ...), its value and the allowed range.
  void validate() const;
};

/// The string run and its comparison with the exact solution. Summary keys (besides the string run's,
/// among them energy_residual, momentum_residual and events): those of every comparison
/// (exact_comparison_summary, contact_compare.hpp: problem = "pulley", nodes, the stop and the first
/// lift-off's t and x against t*, x* = ℓ_free/2 + u*, max_abs_err_x; x is the longer side's hanging
/// length ℓ_free/2 + u, u half the difference of the two ends' heights), and
///   u0, R                       the setup (m),
///   u_lift_off_exact            u* (m),
///   max_abs_err_tension_short   max over the steps of |τ2 − λ x2 (g + ẍ)| (N): the tension where the
///                               shorter side meets the pulley, extrapolated linearly in height to the
///                               pulley's centre (y = 0) from the two hanging links below its first
///                               held node; x, ẍ exact,
///   max_abs_err_tension_long    the same for τ1 = λ x1 (g − ẍ) where the longer side leaves it (N),
///   mean_abs_err_tension_short, mean_abs_err_tension_long   their means over the steps (N),
///   mean_err_tension_short, mean_err_tension_long   the means of the signed errors (N),
///   max_rel_err_tension         the larger maximum over λ g ℓ,
///   tension_steps               the steps at which both were measured (each side needs two hanging links
///                               below the pulley), up to the string's lift-off (PulleyLiftOff: the zero of
///                               its margin, or the pulley's release of the shorter side's first held node
///                               if sooner; the exact solution holds up to t* only, and the string's
///                               unwrapping after its release is no wrapped chain).
/// exact: at the string's step times, t, x, x_dot, u, tension_short, tension_long (N), and
/// lift_off_margin = (τ2 − λ ẋ²)/R (N/m), the contact force per length where the shorter side meets the
/// pulley: it reaches zero at the lift-off.
using PulleyComparison = ExactComparison;

/// The tension where a hanging side meets the pulley's horizontal diameter (y = 0, the pulley's centre at
/// the origin), extrapolated linearly in height from the two highest links of the side that lie wholly
/// below it, found going up from its end node `end` by `step` (+1 from node 0, the shorter side's end; −1
/// from the last node); NaN if there are not two.
double tension_at_pulley(const Points<2>& x, const Eigen::VectorXd& tension, int end, int step);

/// The string's lift-off off the pulley as `compare pulley` measures it: the first zero of its margin
/// τ2 − λ ẋ² (its tension where the shorter side meets the pulley, its speed), interpolated linearly
/// between the accepted steps where it changes sign. Fed step by step (a scene's run measures it too:
/// tests/convergence/test_contact.cpp). Where the pulley lets go of the shorter side's first held node
/// before a step shows that zero (`released`: the contact module's lift-off, which reads the node's share
/// of the arc), the margin after it is the unwrapping string's, not the wrapped chain's: the zero is then
/// extrapolated from the last three steps before the release (the parabola through their margins; the
/// line through the last two where there are only two).
struct PulleyLiftOff {
  double x_offset = 0;      ///< ℓ_free/2 (m): the longer side's hanging length is x_offset + u
  std::optional<double> t;  ///< the lift-off time (s), once found
  std::optional<double> x;  ///< the longer side's hanging length there, interpolated as t (m)
  /// The step at time `t_step` with margin τ2 − λ ẋ² (N) and u (m, half the difference of the ends' heights).
  void add(double t_step, double margin, double u);
  /// The shorter side's first held node has been let go since the last step added.
  void released();

 private:
  struct Step {
    double t = 0, margin = 0, u = 0;
  };
  std::array<Step, 3> last_{};  // the last steps added, the latest first
  int have_prev_ = 0;           // how many (up to 3)
};
PulleyComparison compare_pulley_with_exact(const PulleyCaseSetup& setup);

}  // namespace chainsim
