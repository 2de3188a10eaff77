#pragma once
/// @file split_link_front.hpp
/// What a fold and a kink share (front_kind.hpp): a front at a free point x0 inside one link, the
/// *split link* (a, b) between arc A (s < s0, its last node a) and arc B (s > s0, its first node b),
/// whose material it splits into partial links l⁻ (on node a) and l⁺ = h − l⁻ (on node b). The layout,
/// the stencil, the end tensions at a and b, the partial links' potential, the crossings (the front
/// reaches a or b) and what a crossing does (the node moves to the other arc, the material of the two
/// links whose split changes moving with its momentum: mass parcels) are here; the geometry of the
/// split link and the jump conditions are the kind's (FoldFront, KinkFront: its `evaluate`).
#include "shocks/front_kind.hpp"

namespace chainsim {

template <int dim>
class SplitLinkFront : public FrontKind<dim> {
 public:
  void cut(FrontLayout& layout) override;
  std::vector<int> stencil(const StringModel<dim>& model) const override;
  bool has_load_derivatives() const override { return true; }
  std::optional<double> tension_at(const StringModel<dim>& model, const FrontState<dim>& state,
                                   int node) const override;
  /// The partial links as straight segments from their nodes to x0 (state.position).
  double potential_moment(const StringModel<dim>& model, const FrontState<dim>& state, const Vec<dim>& g) const override;
  /// g[0] = l⁺ (the front reaches arc B's first node), g[1] = l⁻ (arc A's last node), less end_margin.
  void crossings(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  int second_direction() const override { return -1; }
  /// The node the front reaches moves to the other arc; the mass of the two links whose split changes
  /// moves with its velocity (momentum exact). Stops at an end of the string.
  EventAction cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) override;
  /// The split link becomes a full link again: arcs A and B merge, its material re-lumped ½–½ with its
  /// momentum (mass parcels, as at a crossing).
  void remove(StringModel<dim>& model, const FrontState<dim>& state) override;
  /// The weight of a partial link of material length l that continues the full link (q, p) straight beyond its
  /// node p (its material runs from x_p along u = (x_p − x_q)/|x_p − x_q| to the front) acting at the partial
  /// link's midpoint x_p + ½ l u, where potential_moment counts its potential: the node masses put the weight
  /// W = λ l g on p (g the model's uniform field), and this adds its moment about p as the couple ±(l / 2|x_p − x_q|)
  /// W⊥ on p and q (W⊥ the part of W across the link), whose power ½ l W·u̇ is the weight's work on the partial
  /// link as it turns with the link (docs/model.md §10, "The partial links' weight"; the edge front uses it too).
  /// Nothing without a uniform field.
  static void add_partial_weight(const StringModel<dim>& model, int p, int q, double l, double lambda,
                                 Points<dim>& force);

 protected:
  /// kLastPartial h where the front's node on that side (B's first for `plus`, A's last otherwise) is a free end of
  /// the string, whose mass vanishes with its partial link: the crossing there is the stop "has reached the end"
  /// (cross), taken that far before the end. 0 elsewhere (a node inside the string keeps its other link's mass; a
  /// prescribed end has no mass to lose).
  double end_margin(const StringModel<dim>& model, bool plus) const;
  /// Whether `node` is a free (not prescribed) end of an open string.
  static bool is_free_end(const StringModel<dim>& model, int node);
  /// The unit tangent of the link i → j and its rate (the part of (v_j − v_i) across it over its length).
  static Vec<dim> link_tangent(const StringModel<dim>& model, int i, int j, const char* what, Vec<dim>& rate);
  /// Mass parcels: link j's share on its start node changes by `delta` (kg), the material moving with the
  /// velocity of the node it leaves; `mass` and `mom` hold the nodes lo, lo + 1, … (momentum exact).
  static void move_parcel(const StringModel<dim>& model, int lo, int j, double delta, Eigen::Ref<Eigen::VectorXd> mass,
                          Points<dim>& mom);
  /// The velocities of the free nodes lo, lo + 1, … in an arc from their parcels' mass and momentum.
  static void set_velocities(StringModel<dim>& model, int lo, const Eigen::Ref<const Eigen::VectorXd>& mass,
                             const Points<dim>& mom);
  /// After a crossing the re-layout may leave the front outside its new split link (l⁻ or l⁺ < 0: a touchdown
  /// front's landing where the arc's first two links meet at an angle, a kink's arms that meet beyond the new
  /// node where the string turns sharply next to it): harmless while the front moves back in, fatal if it moves
  /// further out, past a crossing's root that ARKODE (which sees sign changes only) no longer finds, until the
  /// node beyond loses its mass. The margin is negative where the front lies more than kMaxOutside h out on a side
  /// and moves away from the link on that side (−1 h … 0), 1 otherwise; watched from a crossing (watch_outside)
  /// until the front is first seen inside, not before a crossing, where a step past its root would meet this one
  /// too and be taken again (the 3D drawn string took 1,880 right-hand sides instead of 1,009).
  double outside_margin(const FrontState<dim>& state) const;
  void watch_outside() { relaid_ = true; }
  /// Outside by less than this (per h) is the crossing's own round-off.
  static constexpr double kMaxOutside = 1e-6;

  /// The split link's nodes: arc A's last and arc B's first.
  int node_a(const StringModel<dim>& model) const { return model.arcs()[static_cast<std::size_t>(this->arc_minus)].last; }
  int node_b(const StringModel<dim>& model) const { return model.arcs()[static_cast<std::size_t>(this->arc_plus)].first; }

 private:
  /// Set by a crossing, cleared where outside_margin first sees the front inside its split link.
  mutable bool relaid_ = false;
};

}  // namespace chainsim
