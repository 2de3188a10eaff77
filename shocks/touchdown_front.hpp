#pragma once
/// @file touchdown_front.hpp
/// A touchdown front (front_kind.hpp): where a string lying on a smooth plane leaves it, or a moving
/// arc lands on it, an internal shock of dissipation f that slides along the plane (docs/model.md §10,
/// "A touchdown front"; in 3D "A touchdown front in 3D": e is then the lying part's last link projected on the
/// plane, the split link has two constraints, touchdown_split_constraint (its length, and x0 on the lying link's
/// line), the load on a has a part τ_b along n × e that keeps the front's reaction normal to the plane, and with f > 0
/// the run stops where a moving front's arc leaves out of the plane of e and n, kMaxOffPlaneDeg).
///
/// The string before the front (s < s0, arc A) lies on the plane, held there node by node by the
/// contact module (the surface holds arc A's nodes only: Obstacle::carries, touchdown_surface); the
/// string after it (arc B) is free. The split link (a, b) between A's last node and B's first node
/// holds the front: its material runs along the plane from x_a to x0 and on from x0 to x_b along arc B's
/// first link (b, c), of direction t at the angle θ to the plane (e the plane's direction along arc A,
/// towards larger s; n its outward normal; y_b the height of b):
///     l⁺ = y_b / sin θ,   l⁻ = h − l⁺,   x0 = x_b − l⁺ t,   ṡ0 = −dl⁺/dt,
/// and a constraint keeps the material, C = (x_b − x_a)·e + y_b tan(θ/2) − h = 0 (its gradient on the
/// held node a along e; its net force μ tan(θ/2) n, booked with the front's reaction). With
/// [v] = v_b − v_a the front loads
///     node b:  −τ⁺ t,   τ⁺ = (1 − f sgn ṡ0) λ ṡ0 |[v]|² / (2 (−t·[v]))
///     node a:  τ⁻ e,    τ⁻ = λ ṡ0 [v]·e + τ⁺ cos θ
/// (τ⁺ = (1 − f sgn ṡ0) λ ṡ0², τ⁻ = λ ṡ0² (1 − f sgn ṡ0 cos θ) where the two sides are compatible,
/// [v] = −ṡ0 [t]), which keep the lumped momentum along the plane exact (the front's reaction, the
/// momentum the loads and the material moved from b to a change, is normal to the plane) and work at
/// exactly W_s = −½ f λ |ṡ0| |[v]|². The reaction N n, N = f λ ṡ0 |ṡ0| sin θ on the compatible state
/// (the constraint's share zero there), is what forces.csv shows. A take-off with f > 0 (ṡ0 < 0) would
/// need the plane to pull, and so would a lying part whose motion disagrees with the arc's end (the
/// constraint's multiplier): the front's check stops the run where its reaction reaches zero (a
/// lift-off event); f = 0 peels off without a reaction.
/// Crossings are the split link's (SplitLinkFront), kHysteresis h past a node: a node of B that the front
/// passes (landing) joins A with A's velocity and is put on the plane at h from A's last node, where the
/// contact module holds it; a node of A that it passes (take-off) joins B, put on B's first link at h from
/// B's first node.
#include <algorithm>
#include <string>

#include "shocks/split_link_front.hpp"
#include "solver/contact_module.hpp"

namespace chainsim {

/// The split link's constraint of a 3D touchdown front (docs/model.md §10, "A touchdown front in 3D"), from the
/// positions and velocities of the lying part's last link (p, a) (p < 0: none, e given), of arc B's first link
/// (b, c), the plane (a point and its unit normal n) and the link length h:
///     C = (x_b − x_a)·e + y_b (1 − t·e)/(t·n) − h,
/// e = P (x_a − x_p)/|P (x_a − x_p)| (P = I − n nᵀ), t = (x_c − x_b)/|x_c − x_b|, y_b = n·(x_b − point): l⁻ + l⁺ − h
/// with l⁺ = y_b/(t·n) and l⁻ = (x0 − x_a)·e, x0 = x_b − l⁺ t. In the plane of e and n it is the 2D constraint
/// (1 − cos θ)/sin θ = tan(θ/2). In 3D a second one puts x0 on the lying link's line (lateral_value).
template <int dim>
struct TouchdownConstraint {
  Vec<dim> e = Vec<dim>::Zero(), t = Vec<dim>::Zero(), x0 = Vec<dim>::Zero();
  double cos = 0, sin = 0;  ///< t·e, t·n
  double l_plus = 0, l_minus = 0, s0_dot = 0;  ///< ṡ0 = −dl⁺/dt
  double value = 0;          ///< C
  Points<dim> gradient;      ///< ∂C/∂x at p, a, b, c (p's column zero when p < 0)
  double curvature = 0;      ///< C̈ at zero accelerations
  /// The second constraint, x0 on the lying link's line: D = (x0 − x_a)·b = (x_b − x_a)·b − y_b (t·b)/(t·n),
  /// b = n × e (3D; zero in 2D), with its gradient (same columns) and D̈ at zero accelerations.
  double lateral_value = 0;
  Points<dim> lateral_gradient;
  double lateral_curvature = 0;
};
template <int dim>
TouchdownConstraint<dim> touchdown_split_constraint(const Vec<dim>& xp, const Vec<dim>& xa, const Vec<dim>& xb,
                                                    const Vec<dim>& xc, const Vec<dim>& vp, const Vec<dim>& va,
                                                    const Vec<dim>& vb, const Vec<dim>& vc, bool has_p,
                                                    const Vec<dim>& e_fixed, const Vec<dim>& point,
                                                    const Vec<dim>& normal, double h);

/// A touchdown front on the plane through `point` with unit outward normal `normal`.
template <int dim>
struct TouchdownSpec {
  Vec<dim> point = Vec<dim>::Zero();
  Vec<dim> normal = Vec<dim>::Zero();
  double dissipation = 0;  ///< f, in [0, 1]
  double s0 = 0;           ///< where the initial shape leaves the plane (m)
  std::string name = "effects.surface[0]";  ///< the surface, for messages
};

template <int dim>
class TouchdownFront final : public SplitLinkFront<dim> {
 public:
  /// The run stops when the arc meets the plane at less than this angle (its front is then a
  /// tangential touchdown, no shock, whose position the split link no longer resolves).
  static constexpr double kMinAngleDeg = 5;
  /// The front crosses a node when a partial link reaches −kHysteresis h, not 0 (as the fold's and a heap's
  /// thresholds are moved out): the crossing places the node where the material it carries is at that
  /// moment (a landing node on the plane at h from the lying arc's last node, a lifting node on the arc's
  /// first link at h from its second node), so that s0 runs on continuously and the new split link's other
  /// partial link starts at kHysteresis h, on the positive side of its own threshold (a front that reverses
  /// right after a crossing then crosses back, docs/model.md §10).
  static constexpr double kHysteresis = 1e-8;
  /// 3D, f > 0: the run stops when the arc's tangent t makes more than this angle, asin |t·b|, with the plane of the
  /// lying part's direction e and the normal n (b = n × e: the jump conditions' balance along b, f λ ṡ0² (t·b) = 0,
  /// needs it zero for f > 0 on a moving front; the discrete front books the residual as a sideways load on the lying
  /// end, docs/model.md §10, "A touchdown front in 3D").
  static constexpr double kMaxOffPlaneDeg = 1;
  /// The run stops when, right after a crossing, the front lies more than this (per h) behind the new split link's
  /// node on either side: the crossing left it past its own root (l⁻ or l⁺ < −kHysteresis h), where ARKODE, which sees
  /// sign changes only, would no longer find the next crossing and the front would run past a node until the node
  /// lost its mass (docs/model.md §10, "A falling arc"). Well below one link and well above the crossing's kHysteresis.
  static constexpr double kMaxBehind = SplitLinkFront<dim>::kMaxOutside;

  explicit TouchdownFront(const TouchdownSpec<dim>& spec);

  const char* name() const override { return "touchdown"; }
  const char* placed() const override { return "touchdown"; }
  /// The last node of the lying arc (A), which the surface holds, and all before it.
  int lying_last() const { return lying_last_; }

  void cut(FrontLayout& layout) override;
  void initialize(StringModel<dim>& model) override;
  void evaluate(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass,
                Points<dim>& force) override;
  /// g[0] = l⁺/h + kHysteresis (a landing: the front passes arc B's first node), g[1] = l⁻/h + kHysteresis
  /// (a take-off: it passes arc A's last node).
  void crossings(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  EventAction cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) override;
  /// One: positive while the arc meets the plane at more than kMinAngleDeg, no other node of the arc
  /// reaches the plane, the plane pushes at the front (its reaction's normal component), the lying part's last
  /// full link next to the front is not pushed (its tension, the front's constraint's share included, ≥ 0: a
  /// falling arc lays its material down faster than a lying part at rest moves away, docs/model.md §10, "A falling
  /// arc"), the front lies inside its split link (kMaxBehind), and (3D, f > 0) a moving front's arc stays within
  /// kMaxOffPlaneDeg of the plane of e and n.
  bool checks_need_tensions() const override { return true; }
  int num_checks() const override { return 1; }
  void checks(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  std::string check_failed(const StringModel<dim>& model, const FrontState<dim>& state, double t,
                           int check) const override;
  std::optional<RunEvent> check_event(const StringModel<dim>& model, const FrontState<dim>& state, double t,
                                      int check) const override;

  void constraints(const StringModel<dim>& model, const FrontState<dim>& state,
                   std::vector<NodeConstraint<dim>>& out) const override;
  Vec<dim> constraint_force(const StringModel<dim>& model) const override;
  bool has_constraint_force() const override { return true; }
  Vec<dim> recorded_reaction(const StringModel<dim>& model, const FrontState<dim>& state) const override;

  /// The angle θ (rad) at which the arc leaves the plane, after an evaluation.
  double angle() const { return theta_; }

 private:
  /// The split link's geometry: arc B's first link (b, c) at angle θ to the plane, continued to the plane
  /// at x0; l⁺ = y_b / sin θ, l⁻ = h − l⁺, ṡ0 = −dl⁺/dt.
  struct Geometry {
    int a = 0, b = 0, c = 0;
    Vec<dim> t = Vec<dim>::Zero(), t_perp = Vec<dim>::Zero(), x0 = Vec<dim>::Zero();
    double L = 0, cos = 0, sin = 0, theta_dot = 0, t_w = 0, y = 0, y_dot = 0, tan_half = 0;
    double l_plus = 0, l_minus = 0, s0_dot = 0;
    /// 3D: e, the lying part's direction at the front (its last link (p, a) projected on the plane; along_ when
    /// the lying part is node 0 alone, p = −1), and the split link's constraint (touchdown_split_constraint).
    Vec<dim> e = Vec<dim>::Zero();
    int p = -1;
    TouchdownConstraint<dim> split;
  };
  /// The split link's nodes a, b and the arc's next node c (a geometry with nothing else set yet).
  Geometry nodes(const StringModel<dim>& model) const;
  Geometry geometry(const StringModel<dim>& model) const;
  /// The front's state and the partial links' masses on a and b, from the geometry, e and the tensions.
  void set_state(const StringModel<dim>& model, const Geometry& g, const Vec<dim>& e, double tau_m, double tau_p,
                 FrontState<dim>& s, Eigen::VectorXd& mass) const;
  /// geometry() in 3D (dim = 3; the 2D one keeps its own arithmetic).
  Geometry geometry_3d(const StringModel<dim>& model) const;
  /// evaluate() in 3D (the 2D one keeps its own arithmetic).
  void evaluate_3d(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass, Points<dim>& force);
  /// The margins of checks(): angle, other nodes' heights (per h), take-off.
  struct Margins {
    double angle = 1, height = 1, take_off = 1, off_plane = 1, pushed = 1, inside = 1;
    int low_node = -1, pushed_link = -1;
    double pushed_tension = 0;
  };
  /// The least of the margins.
  static double least(const Margins& m) {
    return std::min({m.angle, m.height, m.take_off, m.off_plane, m.pushed, m.inside});
  }
  Margins margins(const StringModel<dim>& model, const FrontState<dim>& state) const;

  Vec<dim> point_ = Vec<dim>::Zero(), normal_ = Vec<dim>::Zero();
  Vec<dim> along_ = Vec<dim>::Zero();  ///< e at the start (2D: always): the plane's direction along arc A towards larger s
  std::string surface_;
  int lying_last_ = -1;
  double theta_ = 0;
  double elevation_ = 1;  ///< 3D: t·n, the sine of the arc's elevation over the plane, after an evaluation
  double off_plane_ = 0;  ///< 3D: |t·b|, the sine of the arc's angle to the plane of e and n (b = n × e)
  /// The index of this front's constraint in the model's list (constraints() appends it to the list the model
  /// rebuilds from every front), for constraint_force; in 3D the lateral one follows it.
  mutable std::size_t constraint_index_ = static_cast<std::size_t>(-1);
};

/// The surface's obstacle holding the lying arc of `front` only (its nodes up to front.lying_last()).
/// `front` must outlive it.
template <int dim>
void touchdown_surface(const TouchdownFront<dim>& front, Obstacle<dim>& surface);

}  // namespace chainsim
