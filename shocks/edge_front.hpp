#pragma once
/// @file edge_front.hpp
/// An edge front (front_kind.hpp): a point fixed in space (a sharp edge, a peg) over which the string
/// runs, material flowing through it (docs/model.md §8 has the physics, docs/shocks.md the numerics).
///
/// The string runs on through the edge in one arc; the link (a, b = a + 1) whose material holds the
/// edge is bent over the point x0 (StringModel::bend_link): |x0 − x_a| + |x_b − x0| = h, its tension
/// the multiplier τ⁻ of that constraint. The edge adds
///   - the partial links' masses: node a carries λ l⁻ of the bent link, node b λ l⁺ (l∓ its two
///     lengths), so each side's mass is λ × its material length (the scheme is exact for motions
///     along straight sides, as at a heap);
///   - the tension jump of its f as a known load on b: τ⁺ = τ⁻ + [τ], [τ] = −½ f λ sgn(ṡ0) ṡ0² |[t]|²
///     (jump::pinned_tension_plus), which works at −D (jump::pinned_dissipation_rate);
///   - optionally a table: the string on one side lies on the face through the edge (normal n, fixed
///     at the start), which holds it against the uniform field's normal component (a known load
///     −m_i (g·n) n on each of its nodes; no work, the string slides along the face).
/// The edge's reaction F0 = −[τ t] + λ ṡ0² [t] (jump::pinned_reaction) is what forces.csv shows
/// (R_front<k>). It can only push: its root function is jump::pinned_lift_off_margin, and where it
/// reaches zero the chain lifts off the edge and the run stops (an event of the summary).
/// With slack = "allow" the bent link is a unilateral link like the others (the complementarity problem
/// may release it, a snap may catch it: its length l⁻ + l⁺, its rate d(l⁻ + l⁺)/dt, the edge taking the
/// impulse P (e⁻ − e⁺)); the lift-off margin reaches zero before its tension does unless ṡ0 = 0, and a
/// bent link found slack (released at ṡ0 = 0, left slack by a snap, or laid slack) is a lift-off too:
/// the string no longer presses on the edge (docs/model.md §9 "Slack over an edge").
/// Crossing: when node a comes within kCross h of x0 (material flowing from the − side to the +
/// side) it passes to the other side, put just past x0 (x0 + kMirror kCross h t⁺) with its velocity rotated from
/// t⁻ to t⁺ (its speed kept: no energy lost), and the link before it is bent instead; the same the
/// other way; each side moves on rigidly by as much (cross()), so that every link keeps its length.
/// A step over a crossing may end up to kOvershoot h past it, before it is handled: there the bent
/// link's partial lengths are signed (StringModel::bent_sides), so that everything above runs on
/// continuously through the crossing (docs/model.md §8, "Past the point").
#include <optional>
#include <string>

#include "shocks/front_kind.hpp"
#include "solver/contact_module.hpp"

namespace chainsim {

/// An edge (or a peg): the string runs over the point `point` at its material coordinate s0.
template <int dim>
struct EdgeSpec {
  /// Which side of the string lies on a face through the edge (a table).
  enum class Table { kNone, kBefore, kAfter };
  Vec<dim> point = Vec<dim>::Zero();  ///< x0 (m)
  double dissipation = 0;             ///< f of the kink, in [0, 1]
  double s0 = 0;                      ///< the material coordinate where the initial shape passes through x0 (m)
  /// In 3D the edge's line (unit); in 2D zero (the out-of-plane axis). The lift-off cone lies normal
  /// to it. The crossing point is held at x0 (it does not slide along the line).
  Vec<dim> axis = Vec<dim>::Zero();
  Table table = Table::kNone;
};

/// f in [0, 1] (InputError naming `name`.f otherwise).
void check_edge_dissipation(double f, const std::string& name = "edge");

template <int dim>
class EdgeFront final : public FrontKind<dim> {
 public:
  /// Node a crosses the edge when it comes this close to x0 (in links; above the string's collapsed-link floor).
  static constexpr double kCross = 1e-8;
  /// How far past x0 the crossing node is put (in kCross h): past the other root function's zero.
  static constexpr double kMirror = 2;
  /// How far past x0 (in links) a trial stage may carry the bent link's node before it is refused.
  static constexpr double kOvershoot = 1e-3;

  explicit EdgeFront(const EdgeSpec<dim>& spec);

  const char* name() const override { return "edge"; }
  const char* placed() const override { return "edge point"; }
  const Vec<dim>& point() const { return point_; }
  /// The bent link (its start node a).
  int link() const { return link_; }

  void cut(FrontLayout& layout) override;
  void initialize(StringModel<dim>& model) override;
  void evaluate(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass,
                Points<dim>& force) override;
  std::optional<double> tension_at(const StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/,
                                   int /*node*/) const override {
    return std::nullopt;  // the edge is inside an arc: its bent link carries τ⁻
  }
  double potential_moment(const StringModel<dim>& model, const FrontState<dim>& state, const Vec<dim>& g) const override;
  void crossings(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  int second_direction() const override { return -1; }
  EventAction cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) override;
  /// The crossing moves each side along itself: its projection changes K + V by round-off (measured at most
  /// 5e-11 J of 9.81 J on the example and rotated scenes).
  bool exact_crossing() const override { return true; }
  /// The lift-off margin (N), positive while the edge pushes; in 3D also the along-line margin
  /// kAlongLine (τ⁻ + τ⁺ + λ ṡ0²) − |F0·d| (N), positive while the held crossing point asks no force of the
  /// edge along its line (a smooth edge has none: an oblique crossing would slide along it, not built); with a
  /// table, the string beyond the edge outside the table's body (table_body_gap, per h: its side face beneath the
  /// edge is not an obstacle, so a side that swings back under the table would pass into it).
  int num_checks() const override { return kTableCheck + (table_ != EdgeSpec<dim>::Table::kNone ? 1 : 0); }
  /// The table's check comes after the lift-off's (and in 3D the along-line one).
  static constexpr int kTableCheck = dim == 3 ? 2 : 1;
  /// The largest force along a 3D edge's line, per the forces the jump conditions balance there
  /// (τ⁻ + τ⁺ + λ ṡ0²: not |F0|, which falls to zero at a lift-off), before the run stops. Far above the
  /// round-off of F0·d on a line at right angles to the string (measured up to 2.5e-7 of |F0|, the partial
  /// links' directions 1e-8 links long carrying the coordinates' round-off); a 45° crossing is at 0.35.
  static constexpr double kAlongLine = 1e-3;
  void checks(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  std::string check_failed(const StringModel<dim>& model, const FrontState<dim>& state, double t,
                           int check) const override;
  bool checks_need_tensions() const override { return true; }
  std::optional<RunEvent> check_event(const StringModel<dim>& model, const FrontState<dim>& state, double t,
                                      int check) const override;
  /// F0 of the jump conditions at the current tension (without the table's support).
  Vec<dim> recorded_reaction(const StringModel<dim>& model, const FrontState<dim>& state) const override;

  /// The edge's point (a 3D edge's line, ℓ long), and with a table its face (ℓ deep) and the wedge's
  /// other face (ℓ/4 deep), along the sides' initial tangents.
  void draw(int index, ObstacleDrawing& drawing) const override;

  /// The tensions τ⁻, τ⁺ (N) after an evaluation.
  double tension_minus(const StringModel<dim>& model) const { return model.link_tension(link_); }
  double tension_plus(const StringModel<dim>& model) const { return model.link_tension(link_) + jump_; }

 private:
  /// |τ⁻| + |τ⁺| + λ ṡ0² (N): the forces the jump conditions balance at the point (3D's along-line check).
  double along_line_scale(const StringModel<dim>& model, const FrontState<dim>& s) const;
  /// kAlongLine (τ⁻ + τ⁺ + λ ṡ0²) − |F0·d| (N) for the reaction F0 (3D).
  double along_line_margin(const StringModel<dim>& model, const FrontState<dim>& s, const Vec<dim>& reaction) const;
  /// Whether the along-line check is the one that stops the run at this state (3D).
  bool along_line(const StringModel<dim>& model, const FrontState<dim>& s) const;
  /// Signed distances (m) from node a to x0 and from x0 to node b, along the directions the string
  /// arrives at a and leaves b (StringModel::bend_side_direction): a node passing x0 changes their sign,
  /// and the sign of its partial length l∓ with them (StringModel::bent_sides).
  double g_minus(const StringModel<dim>& model) const;
  double g_plus(const StringModel<dim>& model) const;

  Vec<dim> point_ = Vec<dim>::Zero();
  Vec<dim> axis_ = Vec<dim>::Zero();
  typename EdgeSpec<dim>::Table table_ = EdgeSpec<dim>::Table::kNone;
  /// The side a contact surface that ends at this edge holds (edge_table): kNone without one.
  typename EdgeSpec<dim>::Table surface_side_ = EdgeSpec<dim>::Table::kNone;
  template <int d>
  friend Obstacle<d> edge_table(EdgeFront<d>& edge, const Vec<d>& normal, const Vec<d>& inward, bool before,
                                const Vec<d>& edge_axis, std::string name);
  Vec<dim> table_normal_ = Vec<dim>::Zero();  ///< the table's outward unit normal (set at initialize)
  /// The table's top from the edge into the table, normal to the edge's line (set at initialize).
  Vec<dim> table_inward_ = Vec<dim>::Zero();
  /// The node beyond the edge deepest in the table's body and its gap (table_body_gap, m): (−1, +∞) without a table.
  std::pair<int, double> table_body(const StringModel<dim>& model) const;
  /// The table in messages: "under the string before the edge" (or after).
  std::string table_name() const {
    return table_ == EdgeSpec<dim>::Table::kBefore ? "under the string before the edge" : "under the string after the edge";
  }
  int link_ = -1;
  /// The sides' tangents at the edge at the start (the faces drawn along them).
  Vec<dim> start_minus_ = Vec<dim>::Zero(), start_plus_ = Vec<dim>::Zero();
  /// Moves the nodes first … last_minus (before the edge) and first_plus … last (after it) by `step` (m)
  /// along the string: from this edge along `minus` and `plus`, and beyond another edge's bent link (a
  /// second edge or peg on the string) along that edge's line on its far side, so that the material
  /// moves through every edge by the same length (a crossing, the nudge off a node at the start).
  void shift_sides(StringModel<dim>& model, int first, int last_minus, int first_plus, int last, double step,
                   const Vec<dim>& minus, const Vec<dim>& plus) const;
  /// The direction of the string before (`before`) or after another edge's bent link j: along its part
  /// to or from the point if that is longer than half a link, else along the link beyond it.
  Vec<dim> side_direction(const StringModel<dim>& model, int j, bool before) const;
  /// Bends link `a` over x0 (StringModel::bend_link, which keeps its directions for an arc's end node);
  /// `received` +1 (−1) after a crossing that put a node on the + (−) side: that side's partial length
  /// stays unsigned (cross()); 0 at the start: both signed.
  void set_link(StringModel<dim>& model, int a, int received = 0);
  // Of the last evaluation: the tangents on either side, the tension jump [τ] (N).
  Vec<dim> t_minus_ = Vec<dim>::Zero(), t_plus_ = Vec<dim>::Zero();
  double jump_ = 0;
  bool slack_ = false;  ///< the bent link was slack at the last evaluation (slack = allow)
};

/// A table that ends at `edge` (docs/model.md §10, "A table bounded by its edge"): the plane through the
/// edge's point with the outward unit normal `normal`, existing only on the side `inward` (a unit
/// direction in the plane, normal to the edge's line, from the edge into the table), holding the nodes
/// on the table's side of the edge in the material (before it: s < s0; else after it) — the side the
/// edge front's bent link leaves them on. The contact module holds them (make_contact_module, with the
/// edge's front tracker as its inner module); the edge keeps its table = kNone. `edge` must outlive it.
template <int dim>
Obstacle<dim> edge_table(EdgeFront<dim>& edge, const Vec<dim>& normal, const Vec<dim>& inward, bool before,
                         const Vec<dim>& edge_axis, std::string name);

}  // namespace chainsim
