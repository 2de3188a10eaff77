#pragma once
/// @file kink_front.hpp
/// A kink front (front_kind.hpp): a conservative internal shock (f = 0) at a corner of the string between
/// the arc before and the arc after it, its arms at any angle (docs/model.md §2.5, docs/shocks.md). The
/// split link's bookkeeping (layout, crossings, mass parcels) is SplitLinkFront's.
#include <algorithm>
#include <cmath>

#include "shocks/split_link_front.hpp"

namespace chainsim {

/// A kink between the arc before and the arc after s0.
struct KinkSpec {
  double s0 = 0;  ///< initial material coordinate of the kink (m), in (0, ℓ)
  /// Not in the string at the start: inserted where a kink forms ([solver] kinks = "insert"), the tangent's
  /// turn over `window` (m of material) first passing `turn_deg`.
  bool inserted = false;
  double turn_deg = 90;
  double window = 0;
};

template <int dim>
class KinkFront final : public SplitLinkFront<dim> {
 public:
  explicit KinkFront(const KinkSpec& spec);

  /// The kink's arms turn by at least this angle: its geometry divides by |t⁻ − t⁺|², and its jump
  /// [v] = −ṡ0 [t], |[t]| = 2 sin(turn/2), vanishes with the turn. A kink that straightens out to it dissolves
  /// (check 1), as one at rest does; a kink that starts straighter is refused.
  static constexpr double kMinTurnDeg = 1;
  /// The kinked link's chord |x_b − x_a| is at most h for arms that meet at x0; the run stops when it
  /// passes this (in units of h): the link's material no longer reaches across.
  static constexpr double kMaxChord = 1.02;
  /// A crossing re-lays the kink where its new arms meet; where the string turns sharply one link beyond the node
  /// crossed, they meet outside the new kinked link, and the node there keeps λ (h/2 − outside) of material. The
  /// run stops at a crossing that would put the kink more than this (per h) outside: half the node's material
  /// (at half a link it would keep none, and the projection after the crossing moved a kink re-laid 0.44 h
  /// outside past that: a shaken U on 401 nodes "degenerated", node 62 without mass; docs/model.md §9).
  static constexpr double kMaxRelaidOutside = 0.25;

  const char* name() const override { return "kink"; }
  const char* placed() const override { return "kink"; }

  void check_initial(const FrontState<dim>& state) const override;
  /// A kink to be inserted takes no share of the initial layout.
  void cut(FrontLayout& layout) override;
  /// cos(turn_deg) subtracted from the smallest cosine of the turn between the links at either end of a
  /// window of material (KinkSpec::window) in one arc: negative once a window turns by more than turn_deg.
  double formation_margin(const StringModel<dim>& model) const override;
  /// The formation window's half width in links on links of h: m = kink_window / 2h rounded, at least 1 (the window is
  /// 2m links, centred on a link, and the links at its ends are compared).
  static int window_half_links(double window, double h) {
    return std::max(1, static_cast<int>(std::lround(window / (2 * h))));
  }
  /// In the link whose neighbours turn most near the sharpest window (its arms' meeting point l⁻ inside it),
  /// its neighbouring links taken taut.
  bool insert(StringModel<dim>& model) override;
  std::string where_formed(const StringModel<dim>& model) const override;
  void evaluate(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass,
                Points<dim>& force) override;
  /// The rest of the compatibility [v] = −ṡ0 [t] (docs/model.md §2.5): the arms meet at x0,
  /// w × d = 0 with w = x_b − x_a − h t_B and h d = h (t_A − t_B) (the arms' links as chords, so that
  /// C is quadratic in the positions): one constraint in 2D, its two components normal to d in 3D.
  void constraints(const StringModel<dim>& model, const FrontState<dim>& state,
                   std::vector<NodeConstraint<dim>>& out) const override;
  /// The string's linearisation does not include the constraint: implicit methods solve their Newton
  /// systems with GMRES, whose products J v (difference quotients of the right-hand side) honour it.
  bool has_load_derivatives() const override { return false; }
  /// A kink that reaches a held end (the arc between it and the end down to one link, the end prescribed) is
  /// absorbed there (docs/model.md §2.5, "A kink at a held end"): the tracker removes it and the velocities
  /// jump by the support's impact.
  bool absorbed(const StringModel<dim>& model, const FrontState<dim>& state, int e0) const override;
  /// Stops where an arc would be left without a full link (its direction t∓ is that link's).
  EventAction cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) override;
  /// Three: (0) positive while the chord is within kMaxChord h; (1) the kink carries a shock (shock_margin) and
  /// its arms turn by more than kMinTurnDeg (where either reaches zero the kink dissolves, `dissolves`); (2) the front
  /// inside its kinked link or moving back into it after a crossing (SplitLinkFront::outside_margin: where the
  /// string turns sharply next to the new kinked link its arms meet beyond the node just crossed, and a kink that
  /// then turns back would run on past the crossing's root until a node lost its mass).
  int num_checks() const override { return 3; }
  void checks(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  /// Check 1's arms read the tension solve (a released arm).
  bool checks_need_tensions() const override { return true; }
  /// Check 0 no: a crossing re-lays the kinked link with its arms not meeting (the least squares of §2.5; on the
  /// swinging U, 201 nodes, its chord is 1.035 h right after the crossing at t = 0.4285 s), and the drift
  /// control brings the chord back within kMaxChord h; the check is watched from the next sign change
  /// (docs/model.md §9, "The crossing breaks the jump conditions"). Check 1 no: it dissolves the kink, and the
  /// tracker dissolves a kink whose check 1 a crossing leaves negative at once. Check 2 yes.
  bool check_after_events(int check) const override { return check == 2; }
  /// Check 1 takes the kink out of the string: it carries no shock any more (docs/model.md §9, "A kink that comes
  /// to rest").
  bool dissolves(int check) const override { return check == 1; }
  std::string check_failed(const StringModel<dim>& model, const FrontState<dim>& state, double t,
                           int check) const override;

 private:
  double turn_margin(const FrontState<dim>& state) const;
  /// Positive while the kink carries a shock: its speed ṡ0 keeps the sign it had after its insertion or last
  /// crossing (τ = λ ṡ0², so where ṡ0 passes zero the tension at the kink does, the jumps [v] = −ṡ0 [t] and
  /// [τ t] vanish, and the kink is a corner at rest that needs no front), and, where slack is allowed, each arm's
  /// link is taut or, released by the tension solve, within the slack gap of its length (an arm that goes slack
  /// carries no τ = λ ṡ0², and the kink's geometry, straight arms of full links, no longer holds: its arms met
  /// 0.4 h apart on the driven catenary of issue 27, and the energy drifted by 9.2e-6 J).
  double shock_margin(const StringModel<dim>& model, const FrontState<dim>& state) const;
  /// Where the arms meet in the kinked link (a, b): l⁻ = w·d / |d|², the least-squares solution of
  /// x_b − x_a = l⁻ t_A + (h − l⁻) t_B, with d = t_A − t_B (dd = |d|²) and w = x_b − x_a − h t_B.
  static double meeting_point(const Vec<dim>& d, double dd, const Vec<dim>& w) { return w.dot(d) / dd; }

  double chord_ = 0;  ///< |x_b − x_a| / h of the kinked link
  KinkSpec spec_;
  /// The links at either end of the sharpest window at the last formation_margin (−1: none).
  mutable int sharpest_ = -1;
  /// The sign of ṡ0 after the insertion or the last crossing (0: not yet seen), for shock_margin.
  mutable int sense_ = 0;
};

}  // namespace chainsim
