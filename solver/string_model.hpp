#pragma once
/// @file string_model.hpp
/// The discrete inextensible string as an ODE system (DESIGN.md §1, §3).
///
/// Momentum per free node i (the tension T_j acts along the link unit vector e_j, from node j towards
/// node j+1):
///
///     m_i a_i = F_i + T_i e_i − T_{i−1} e_{i−1}
///
/// with the applied forces F_i of the scene's effects (forces.hpp). The tensions come from the
/// tension system (tension_system.hpp), solved at every right-hand side. Nodes with a prescribed
/// motion (fixed or driven ends) are not in the ODE state; their position, velocity and acceleration
/// come from their EndPath.
///
/// ODE state y = [ x of the free nodes (dim each, node order) | v of the free nodes | W_applied ].
/// The last component integrates the power of the non-conservative effects and of the drivers,
///     dW/dt = Σ_free F_nc,i · v_i + Σ_prescribed (m_i a_i − m_i g − (tension force)_i) · v_i,
/// as an extra ODE component (so it is error-controlled like the rest), and the ledger
///     drift = K + V − (K0 + V0) − W_applied,   K = ½ Σ m_i |v_i|², V = −Σ m_i g·x_i (all nodes),
/// vanishes for the exact solution.
///
/// Drift control: Baumgarte stabilisation of the link constraints C_j = (|Δx_j|² − h_j²)/2,
///     C'' + 2α C' + β² C = 0,   α = β = 1/τ_b,
/// a critically damped return of each constraint error with the user's time scale τ_b
/// (StringModelOptions::stabilization_time). τ_b should be long compared with the step size (the
/// term adds eigenvalues −1/τ_b, harmless to an explicit method when τ_b ≫ h) and short compared
/// with the run; it does not change the exact solution, for which C = C' = 0. τ_b = 0 turns it off.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "mesh/chain.hpp"
#include "forces.hpp"
#include "integrator.hpp"
#include "tension_system.hpp"

namespace chainsim {

struct StringModelOptions {
  /// Baumgarte time scale τ_b (s) of the link-constraint stabilisation (α = β = 1/τ_b); 0 = off.
  double stabilization_time = 0;
  /// Tension solver: "auto", "tridiagonal", "klu" or "eigen" (tension_system.hpp).
  std::string backend = "auto";
  /// Check for slack (negative tension) at accepted steps (StringModel::check_slack).
  bool check_slack = false;
  /// Slack means T_j < −slack_tolerance · max_k |T_k| (relative, so round-off is not slack).
  double slack_tolerance = 1e-8;
  void validate() const;
};

template <int dim>
class StringModel final : public OdeSystem {
 public:
  /// The model of `chain` (its current positions and velocities are the initial state) under the
  /// given forces, with the listed nodes prescribed. Throws InputError on bad input.
  StringModel(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
              std::vector<PrescribedNode<dim>> prescribed, const StringModelOptions& options);

  // --- OdeSystem ----------------------------------------------------------------------------
  int size() const override { return 2 * dim * num_free_ + 1; }
  void rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) override;

  // --- set-up -------------------------------------------------------------------------------
  /// Puts the prescribed nodes on their paths at t0, then projects the positions and velocities of
  /// the chain onto the link constraints (|Δx_j| = h_j and Δx_j·Δv_j = 0) by the smallest
  /// mass-weighted correction, keeping prescribed nodes. Returns the largest position correction (m).
  /// Throws InputError if the projection does not converge (e.g. fixed ends further apart than the
  /// string is long).
  double make_consistent(double t0);
  /// The ODE state of the chain's current positions and velocities, with W_applied = 0.
  Eigen::VectorXd state_from_chain() const;

  // --- evaluation ---------------------------------------------------------------------------
  /// All node positions and velocities at (t, y) (prescribed nodes from their paths).
  void unpack(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Points<dim>& x, Points<dim>& v) const;

  /// Everything at one state (one tension solve).
  struct Snapshot {
    double t = 0;
    Points<dim> x, v, a;            ///< positions, velocities, accelerations of all nodes
    Eigen::VectorXd tension;        ///< T_j (N)
    double kinetic = 0;             ///< K (J)
    double potential = 0;           ///< V (J)
    double work = 0;                ///< W_applied (J)
    double power = 0;               ///< dW_applied/dt (W)
    double max_violation = 0;       ///< max_j | |Δx_j| − h_j | / h_j
    double max_rate_violation = 0;  ///< max_j |e_j·Δv_j| (m/s)
  };
  Snapshot snapshot(double t, const Eigen::Ref<const Eigen::VectorXd>& y);

  /// max_j | |Δx_j| − h_j | / h_j at (t, y), without a tension solve.
  double max_constraint_violation(double t, const Eigen::Ref<const Eigen::VectorXd>& y) const;
  /// Throws NumericalError naming the link, its tension and t if some T_j < −slack_tolerance·max|T|.
  void check_slack(double t, const Eigen::Ref<const Eigen::VectorXd>& y);

  // --- access -------------------------------------------------------------------------------
  const Chain<dim>& chain() const { return chain_; }
  Chain<dim>& chain() { return chain_; }
  const std::vector<std::unique_ptr<Force<dim>>>& forces() const { return forces_; }
  const std::vector<PrescribedNode<dim>>& prescribed() const { return prescribed_; }
  const StringModelOptions& options() const { return options_; }
  bool is_prescribed(int node) const { return slot_[node] < 0; }
  int num_free_nodes() const { return num_free_; }
  int work_index() const { return size() - 1; }
  /// Baumgarte coefficients α, β (1/s).
  double alpha() const { return alpha_; }
  double beta() const { return beta_; }
  TensionSystem& tension_system() { return *system_; }
  long tension_solves() const { return system_->num_solves(); }
  /// Tensions and accelerations of the last evaluation (rhs or snapshot).
  const Eigen::VectorXd& tensions() const { return system_->solution(); }
  const Points<dim>& accelerations() const { return a_; }
  /// The constant vector g of the gravity effect (zero without gravity).
  Vec<dim> gravity() const;

  /// Evaluates accelerations a_ (and tensions) from all-node x, v at time t; returns dW/dt.
  /// Public for tests: the core of rhs().
  double evaluate(double t, const Points<dim>& x, const Points<dim>& v);

 private:
  void links(const Points<dim>& x, const Points<dim>& v);
  void assemble_matrix();

  Chain<dim> chain_;
  std::vector<std::unique_ptr<Force<dim>>> forces_;
  std::vector<PrescribedNode<dim>> prescribed_;
  StringModelOptions options_;
  std::unique_ptr<TensionSystem> system_;
  std::vector<int> slot_;        // node -> index among free nodes, or -1 if prescribed
  std::vector<int> path_of_;     // node -> index into prescribed_, or -1
  Eigen::VectorXd w_;            // 1/m_i for free nodes, 0 for prescribed ones
  int num_free_ = 0;
  double alpha_ = 0, beta_ = 0;
  // workspace
  Points<dim> x_, v_, a_, force_, force_nc_, tension_force_, b_;
  Points<dim> dx_, dv_, e_;
  Eigen::VectorXd l_;
};

}  // namespace chainsim
