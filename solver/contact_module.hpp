#pragma once
/// @file contact_module.hpp
/// The module of rigid obstacles the string touches along arcs ([[effects.surface]],
/// [[effects.cylinder]]; docs/model.md §10): smooth one-sided planes and cylinders (circles in 2D)
/// that the string's nodes may not pass through. What it adds to the one discrete string
/// (string_module.hpp):
///   - the nodes held on a surface (StringModule::node_contacts): while held, a node's gap stays zero
///     and its normal force N ≥ 0 is the multiplier of that constraint, eliminated node by node from
///     the tension system (StringModel: the held node's inverse mass becomes w P, P = I − n nᵀ, so
///     the system stays tridiagonal along the string);
///   - two root functions: the smallest gap of a free node (a landing: the node is held, and the
///     velocities are projected, mass-weighted, onto the constraints — a perfectly inelastic impact,
///     whose energy is booked in W_impacts and whose impulse in the momentum ledger), and the smallest
///     normal force of a held node (a lift-off: the node is let go, and so is every other held node
///     whose force would then pull, one at a time, most negative first);
///   - the ledgers W_contact (J: the work of the contact forces, zero on the exact solution; it books
///     the drift control's share), W_impacts (J, ≤ 0: what the impacts dissipated, Carnot's loss
///     −½ Σ m_i |Δv_i|²), W_impacts_supports (J: the work of the driven supports' impulses in the impacts, which
///     keep the driven nodes on their paths; zero at fixed ends: docs/model.md §10) and the impulse of all
///     external forces (the momentum ledger p − p0 − impulse, closed across impacts);
///   - the recorded quantities impacts and lift_offs (series.csv): how many landings and lift-offs; each
///     lift-off is also a run event (StringModule::run_events: the summary's `events`, the first 100 of each
///     obstacle, merged in time order with the inner module's) and counted per obstacle
///     (StringModule::lift_off_totals: `contact_lift_offs`; docs/model.md §10, "Lift-offs in the summary");
///   - its drawing for the ParaView output (Obstacle::draw);
///   - Coulomb friction on obstacles with μ > 0 (docs/model.md §10, "Friction"): a held node slides
///     (force −μ N t̂, NodeContact::slide) or sticks (held completely, NodeContact::stuck); two more
///     root functions, a sliding node's tangential speed along its direction of sliding (a stop:
///     the node sticks if the force that holds it is inside the cone, |F_t| ≤ μ N) and the smallest
///     μ N − |F_t| of a stuck node (a slip); the ledger W_friction (J, ≤ 0) and the quantities sticks
///     and slips. Without friction none of this exists: the module is the smooth one, bit for bit.
/// A string with fronts (heaps, folds, edges) keeps its front tracker: this module wraps it
/// (wrapping_module.hpp), passes its layout, masses, forces, ledgers, events and fronts through, and
/// adds the held nodes, its ledgers and root functions after the tracker's (docs/model.md §10, "Contact
/// with fronts"). A plane may end at an edge front (a table and its edge): it then holds only the nodes
/// on the table's side of the edge in the material (Obstacle::carries), and only where it exists.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "string_module.hpp"

namespace chainsim {

/// One rigid obstacle.
template <int dim>
struct Obstacle {
  enum class Kind { kPlane, kCylinder };
  Kind kind = Kind::kPlane;
  Vec<dim> point = Vec<dim>::Zero();   ///< plane: a point of it; cylinder: a point of its axis (the centre in 2D)
  Vec<dim> normal = Vec<dim>::Zero();  ///< plane: its unit normal, towards the side the string is on
  Vec<dim> axis = Vec<dim>::Zero();    ///< cylinder in 3D: its unit axis (unused in 2D)
  double radius = 0;                   ///< cylinder (m)
  double mu = 0;                       ///< Coulomb's coefficient of friction (≥ 0; 0: smooth)
  /// A smooth circle in 2D whose wrapped string lies on it link by link (docs/model.md §10, "Links along
  /// the arc"): the links between two held nodes run along the arc (R θ = h), a link with one end or
  /// both ends free runs round it from the tangent points of its free ends (StringModel::
  /// bend_link_on_circle), nodes land where their link meets the circle tangentially and leave it where
  /// their link's arc runs out, and a held node lifts off where its force and its share of its links'
  /// reactions, per length, would pull. Otherwise the nodes alone are held (the links are chords).
  bool arc_links = false;
  std::string name;                    ///< for messages: "effects.surface[0]"
  /// A plane bounded by an edge (a table): the unit direction in the plane, normal to the edge's line,
  /// from the edge (at `point`) into the table; zero for an unbounded plane. Beyond the edge there is
  /// no surface: gap() is the distance from the edge's line there.
  Vec<dim> inward = Vec<dim>::Zero();
  Vec<dim> edge_axis = Vec<dim>::Zero();  ///< a bounded plane in 3D: its edge's unit line (zero in 2D)
  /// Which nodes the obstacle may hold (all when empty): a table bounded by an edge front holds the
  /// nodes on its side of the edge in the material (the front moves a node across when it passes).
  std::function<bool(int node)> carries;
  bool may_hold(int node) const { return !carries || carries(node); }
  /// The signed distance of x from the surface (m), > 0 outside, its outward unit normal there, and
  /// the gap's second derivative at zero acceleration for a velocity v (m/s²). `held`: of a node held
  /// on the surface, for which a bounded plane goes on past its edge: the edge front takes the node off
  /// the table at its crossing root, and until then (a trial stage of the step that holds that root
  /// may carry the node a little past the edge) its constraint stays the plane's; the distance from
  /// the edge's line there (a free node's gap) would turn its normal and its normal force at once, a
  /// root of the lift-off function that comes before the crossing's.
  double gap(const Vec<dim>& x, bool held = false) const;
  Vec<dim> outward(const Vec<dim>& x, bool held = false) const;
  double curvature(const Vec<dim>& x, const Vec<dim>& v) const;
  /// An orthonormal basis of the surface's tangent space at x, carried along with the surface (2D:
  /// the outward normal turned by +90°; 3D plane: a fixed basis; 3D cylinder: the axis and axis × n),
  /// in which a sliding node keeps the direction it slides in.
  Eigen::Matrix<double, dim, dim - 1> tangents(const Vec<dim>& x) const;
  /// Adds its drawing for the ParaView output (ObstacleDrawing, cell data obstacle = `index`), sized to
  /// `nodes` (the string's, m) plus `margin` (m): a plane's segment (2D) or rectangle (3D) spanning their
  /// projections on it; a cylinder's circle (2D, a polyline), or in 3D its two end circles, at the ends
  /// of their projections on its axis, joined by a few generators.
  void draw(int index, const Points<dim>& nodes, double margin, ObstacleDrawing& drawing) const;
};

/// The contact module of `obstacles` (non-empty) around `inner`, the fronts' module (nullptr: a string
/// without fronts). A node that starts within kInitialContact of its length h from a surface is held
/// on it; one further inside is refused (InputError). On the consistent initial state (StringModule::start)
/// the held nodes whose force pulls are let go and a node that the start's projection carried into a surface
/// lands at t = 0 (docs/model.md §10, "At the start").
template <int dim>
std::unique_ptr<StringModule<dim>> make_contact_module(std::vector<Obstacle<dim>> obstacles,
                                                       std::unique_ptr<StringModule<dim>> inner = nullptr);

/// A cylinder of radius R is resolved by links no longer than R: with thinner links in node contact it is a
/// polygon of one or two nodes, and with links along the arc it is wrapped exactly but its lift-off, where the
/// tension falls to λ v² over a curvature 1/R, is read on a link that spans the whole contact (measured with
/// `chainsim compare pulley`, links along the arc: the lift-off 0.6-7 % early at R = h/2, within 6e-4 at R = h,
/// 3e-5 at R = 2h, 4e-6 at R = 4h; docs/model.md §10). The fewest nodes of a string of `length` m whose links are no longer than
/// R / `per_radius`: ceil(per_radius · length / R) links, one node more on an open string.
inline long nodes_resolving_radius(double radius, double length, bool closed, double per_radius = 1) {
  return static_cast<long>(std::ceil(per_radius * length / radius)) + (closed ? 0 : 1);
}
/// Links along the arc resolve a cylinder's lift-off with links no longer than R / kArcLinksPerRadius: at R = h the
/// heavy Atwood chain's lift-off is within 6e-4 of t* on 51 to 201 nodes, at R = 2h within 3e-5 (u0 = 0.05 m; with
/// u0 = 0.1 m, 7e-6 s), at R = 4h within 4e-6 (docs/model.md §10, "A pulley thinner than the links"; the 2.5e-3 and
/// 1.2e-3 s once measured at R = 2h were compare pulley's, which read the string past the pulley's release).
inline constexpr double kArcLinksPerRadius = 4;

/// A node this share of a link length from a surface at the start is on it (the discretized shape is
/// a polygon inscribed in a curved one); further inside, the scene is refused.
inline constexpr double kInitialContact = 1e-3;

/// How far a point is outside the body of a table (m, < 0 inside): the table's top is the plane through its edge's
/// point with outward unit normal `normal`, and its body lies beneath the top on the side of the edge that `inward`
/// (the top's unit direction from the edge into the table, normal to the edge's line) points to; `r` is the point
/// from the edge's point. The body's side face, beneath the edge, is not an obstacle: a node there has come through
/// it. `margin` (m) moves both faces into the body.
template <int dim>
double table_body_gap(const Vec<dim>& r, const Vec<dim>& normal, const Vec<dim>& inward, double margin) {
  return std::max(normal.dot(r) + margin, margin - inward.dot(r));
}

/// The messages of a node beyond a table's edge that has reached the table's body at t (the run stops) or starts
/// inside it (refused), `r` from the edge's point: one wording for a `[[effects.surface]]` table (the contact module)
/// and an edge's own table (EdgeFront); `table` names it, `see` is the page that says why.
template <int dim>
std::string table_body_reached(int node, double s, const Vec<dim>& edge_point, const std::string& table, double t,
                               const Vec<dim>& r, const Vec<dim>& normal, const Vec<dim>& inward, const std::string& see);
template <int dim>
std::string table_body_start(int node, const std::string& table, const Vec<dim>& r, const Vec<dim>& normal,
                             const Vec<dim>& inward);

/// A free node this share of a link length in from the edge of a table that ends at an edge, and as far beneath
/// its top, has entered the table through its side face (which is not an obstacle): the run stops, located. The
/// margin, kInitialContact's, leaves outside a side hanging flush with the face, whose nodes lie off it by the
/// integration error (at rtol 1e-5, atol 1e-7 a rotated table's hanging side drifted 1e-8 m in, and a margin of
/// 1e-6 h stopped the run there).
inline constexpr double kSideFaceMargin = kInitialContact;

}  // namespace chainsim
