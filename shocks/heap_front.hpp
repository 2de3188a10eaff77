#pragma once
/// @file heap_front.hpp
/// A heap front (front_kind.hpp): a quiescent heap, pinned at a point or lying on a plane, holding
/// the material on one side of the front (front_tracker.hpp has the physics, docs/shocks.md the
/// numerics).
#include "shocks/front_checks.hpp"
#include "shocks/front_kind.hpp"

namespace chainsim {

/// A quiescent heap holding the material on one side of a front.
template <int dim>
struct HeapSpec {
  enum class Side { kBefore, kAfter };
  Side side = Side::kAfter;  ///< kAfter: the heap holds s > s0 (string runs into it at its end, e.g.
                             ///< falling chain); kBefore: it holds s < s0 (feeds the string, sliding chain)
  Vec<dim> point = Vec<dim>::Zero();  ///< x0 (m)
  double dissipation = 0;             ///< f of the internal shock at x0, in [0, 1]; a pot: [−½, 1]
  double s0 = 0;                      ///< initial material coordinate of the front (m), in (0, ℓ)
  /// Unset: the front is pinned at `point` (a hole or an edge the string runs through). Set: the
  /// heap lies on the smooth plane through `point` with this normal (pointing to the string's side),
  /// and the contact slides along the plane where the string meets it (a table under a falling chain).
  std::optional<Vec<dim>> plane_normal;
  /// A pot (side kBefore only): a heap that may push the string out, f < 0 (the chain fountain's pot).
  /// It draws material at τ = (1 + f) λ v² and loses (½ + f) λ v³ ≥ 0 (jump::heap_shock_power). A pinned pot
  /// has a mouth: the nodes it gives out leave along the direction the initial string leaves its point in.
  bool pot = false;
  /// A heap on a plane that is also a contact surface of the string ([effects.plane] surface = true;
  /// solver/contact_module.hpp): a node that reaches the plane away from the contact lands on it (the
  /// contact module's event) rather than being refused as gone through it.
  bool plane_surface = false;
};

/// Throws InputError unless the heap's f is allowed: 0 ≤ f ≤ 1, or −½ ≤ f ≤ 1 for a pot, which must
/// be a start heap (side kBefore). `name` prefixes the message ("heap").
template <int dim>
void check_heap_dissipation(const HeapSpec<dim>& spec, const std::string& name = "heap");

template <int dim>
class HeapFront final : public FrontKind<dim> {
 public:
  /// Throws InputError for a zero plane normal.
  explicit HeapFront(const HeapSpec<dim>& spec);

  const char* name() const override { return "heap"; }
  const char* placed() const override { return "heap point"; }
  bool reservoir() const override { return true; }
  bool after() const { return after_; }
  const Vec<dim>& point() const { return point_; }  ///< x0 (on a plane: a point of the plane)
  bool on_plane() const { return on_plane_; }
  const Vec<dim>& normal() const { return normal_; }  ///< unit normal of the plane, towards the string

  void trim(FrontLayout& layout) const override;
  void cut(FrontLayout& layout) override;
  void initialize(StringModel<dim>& model) override;
  void evaluate(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass,
                Points<dim>& force) override;
  std::vector<int> stencil(const StringModel<dim>& model) const override;
  bool has_load_derivatives() const override { return true; }
  std::optional<double> tension_at(const StringModel<dim>& model, const FrontState<dim>& state,
                                   int node) const override;
  double held_mass(const FrontState<dim>& state) const override;
  void add_held_moment_rate(const FrontState<dim>& state, Vec<dim>& rate) const override;
  void add_held_moment(const FrontState<dim>& state, double before, Vec<dim>& moment) const override;
  void add_support(const FrontState<dim>& state, const Vec<dim>& g, double& mass, Vec<dim>& support) const override;
  double potential_moment(const StringModel<dim>& model, const FrontState<dim>& state, const Vec<dim>& g) const override;
  void crossings(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  int second_direction() const override { return +1; }
  EventAction cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) override;
  /// Held: the curve to the plane keeps the links it was drawn through at the last evaluation (curve_links), when
  /// a snap makes a link next to the end taut again or a separation makes one slack.
  void hold_drawing(bool hold) override { held_links_ = hold ? last_links_ : -1; }

 private:
  /// The arc end at the heap: its end node, the node inside the arc next to it, the node that comes
  /// out of the heap next, and whether the end node can be taken in / a node given out.
  struct End {
    int arc = 0, node = 0, inner = 0, outer = 0;
    bool removable = false, insertable = false;
  };
  End end(const StringModel<dim>& model) const;

  bool after_ = true;  ///< the heap holds s > s0
  double s0_ = 0;
  Vec<dim> point_ = Vec<dim>::Zero();
  bool on_plane_ = false;
  bool plane_surface_ = false;  ///< the plane is a contact surface: other nodes land on it
  Vec<dim> normal_ = Vec<dim>::Zero();
  Vec<dim> last_direction_ = Vec<dim>::Zero();  ///< on a plane, once the arc has no full link left:
                                                ///< the direction its partial link keeps
  Vec<dim> last_curvature_ = Vec<dim>::Zero();  ///< on a plane, once the arc has one full link left:
                                                ///< the second derivative x'' its end keeps
  Vec<dim> partial_mid_ = Vec<dim>::Zero();     ///< the midpoint of the string from the end node to the front
  bool pot_ = false;
  int last_links_ = 0;   ///< the full links the curve to the front took at the last evaluation
  int held_links_ = -1;  ///< >= 0: held (hold_drawing), the curve takes that many links
  Vec<dim> pot_direction_ = Vec<dim>::Zero();   ///< a pinned pot: the direction the string leaves it in (unit)
};

}  // namespace chainsim
