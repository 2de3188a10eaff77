// A heap front: see heap_front.hpp and front_tracker.hpp (the physics), docs/shocks.md (the numerics).
#include "heap_front.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

namespace {
/// A heap takes in an arc's end node when its partial link shrinks to kRemove·h and gives out a new
/// node when it grows to kInsert·h: the partial link stays in [h/2, 3h/2], away from zero length
/// (where its direction is undefined), widened by kCrossingHysteresis·h on either side (front_kind.hpp). The initial layout
/// puts the partial link in [h/2, 3h/2) (up to 1e-9 h), and a crossing moves it by h, so that every
/// root function starts at least ~kCrossingHysteresis·h from zero. With the thresholds at exactly h/2 and
/// 3h/2, a front starting exactly h/2 past a node had a root function that was zero where the
/// integration starts, which ARKODE does not report: the falling chain from eta0 = 0.5 on 4, 6 and 10
/// nodes ran past it unseen and stalled. Crossing it at t = 0 instead left the partial link on the
/// other threshold with a front at rest, whose first steps move it by less than the round-off of
/// the partial link (1e-23 m against 1e-17 m): that sign noise gave the opposite crossing at
/// t = 1.5e-9 s (14 nodes). A band wider by a quarter link avoided both but used the end interpolant
/// further from the nodes and cost the swinging sliding chain its convergence (order -1.08).
constexpr double kRemove = 0.5 - kCrossingHysteresis, kInsert = 1.5 + kCrossingHysteresis;
/// A heap whose content is below this fraction of the string's length (64 ε) is empty.
constexpr double kEmptyHeap = 64 * std::numeric_limits<double>::epsilon();
/// With an edge on the string (a bent link), also below kEmptyLinks h: above the material the edge's
/// crossing moves ahead of time ((kMirror + 1) kCross h = 3·10⁻⁸ h, EdgeFront). With the threshold at
/// 64 ε ℓ alone, a start heap feeding a table edge emptied at the instant the edge passed a node (the
/// heap's s0 and the edge's are a fixed chord apart): the edge's crossing was found first, carried the
/// heap's content from +10⁻¹⁴ m to −3·10⁻¹⁰ m, and ARKODE, which finds only sign changes after a restart,
/// never saw the root: s0 ran on to −0.29 m and the run stopped later with the energy ledger off by 0.21 J.
/// (Without an edge the threshold stays 64 ε ℓ: the stop times of the paper's problems are exact to 10⁻¹².)
constexpr double kEmptyLinks = 1e-7;
/// A string meeting a plane at less than this cosine between its tangent and the plane's normal
/// runs along the plane: the contact point is then ill-defined and the run stops.
constexpr double kGrazing = 1e-3;

/// Why the string's tangent t at the heap (n·t, n the plane's normal) does not run into the plane: at a grazing
/// angle (|n·t| <= kGrazing), or away from it (the string turns back up within the links the heap's curve spans).
std::string not_meeting_plane(double n_t, int node) {
  if (n_t > kGrazing)
    return fmt::format("the string leaves the heap's plane instead of running into it (n·t = {:.3g} > 0 at node {}: "
                       "it turns back within two links of the heap)",
                       n_t, node);
  return fmt::format("the string meets the heap's plane at a grazing angle (n·t = {:.3g} at node {})", n_t, node);
}

/// The string near a heap front: the interpolant in the material coordinate (quadratic through
/// three points, linear through two) of the positions and velocities of the arc's last nodes and, at
/// a pinned front, of the front point (docs/shocks.md, "Second order at a moving front"). Material
/// coordinates are kept relative to the end node's.
template <int dim>
struct EndCurve {
  int n = 0;
  double s[3] = {0, 0, 0};
  Vec<dim> x[3], v[3];
  void add(double s_rel, const Vec<dim>& xi, const Vec<dim>& vi) {
    s[n] = s_rel;
    x[n] = xi;
    v[n] = vi;
    ++n;
  }
  double basis(int j, double t) const {
    double b = 1;
    for (int m = 0; m < n; ++m)
      if (m != j) b *= (t - s[m]) / (s[j] - s[m]);
    return b;
  }
  double basis_derivative(int j, double t) const {
    double d = 0;
    for (int m = 0; m < n; ++m) {
      if (m == j) continue;
      double term = 1 / (s[j] - s[m]);
      for (int q = 0; q < n; ++q)
        if (q != j && q != m) term *= (t - s[q]) / (s[j] - s[q]);
      d += term;
    }
    return d;
  }
  Vec<dim> position(double t) const {
    Vec<dim> r = Vec<dim>::Zero();
    for (int j = 0; j < n; ++j) r += basis(j, t) * x[j];
    return r;
  }
  Vec<dim> velocity(double t) const {
    Vec<dim> r = Vec<dim>::Zero();
    for (int j = 0; j < n; ++j) r += basis(j, t) * v[j];
    return r;
  }
  Vec<dim> slope(double t) const {  // ∂x/∂s
    Vec<dim> r = Vec<dim>::Zero();
    for (int j = 0; j < n; ++j) r += basis_derivative(j, t) * x[j];
    return r;
  }
};

/// A heap front at the current state: where the string meets it and how fast material crosses.
template <int dim>
struct HeapGeometry {
  EndCurve<dim> curve;                     ///< the string near the front, in s − s_k
  double l = 0;                            ///< material length from the end node k to the front
  double w = 0;                            ///< dl/dt: the rate at which the arc gains material
  Vec<dim> e = Vec<dim>::Zero();           ///< unit tangent at the front, from the arc into the heap
  Vec<dim> position = Vec<dim>::Zero();    ///< the front point x0
  Vec<dim> curvature = Vec<dim>::Zero();   ///< on a plane: x'' of the curve (kept for when one link is left)
};

/// The heap front of an arc whose end node is `node` (the heap on the side of larger s when `after`),
/// with `links` full links in the arc. Pinned: the front is the point, l = |x0 − x_k| (the chord,
/// O(h³) from the arc length), and the curve runs through x_{k∓1}, x_k, x0 (the material leaves x0 along
/// the tangent at the speed of the front in the material). On a plane: the curve through the last three
/// nodes (with one full link, the last two and the second derivative it last had; with none, the kept
/// direction) continued to the plane; s0 is its crossing (Newton's method from the last link's), and
/// w follows from differentiating n·(x(s0) − p) = 0.
template <int dim>
HeapGeometry<dim> heap_geometry(const Points<dim>& x, const Points<dim>& v, bool on_plane, const Vec<dim>& point,
                                const Vec<dim>& normal, const Vec<dim>& last_direction, const Vec<dim>& last_curvature,
                                int node, bool after, int links, double h) {
  HeapGeometry<dim> g;
  const double sigma = after ? 1.0 : -1.0;
  const int step = after ? -1 : 1;  // from the end node into the arc
  EndCurve<dim>& c = g.curve;
  if (!on_plane) {
    const Vec<dim> d = point - x.col(node);
    g.l = d.norm();
    if (!(g.l > 1e-9 * h)) throw RecoverableError(fmt::format("the partial link at the heap has collapsed (node {})", node));
    g.w = -v.col(node).dot(d / g.l);
    if (links >= 1) c.add(-sigma * h, x.col(node + step), v.col(node + step));
    c.add(0, x.col(node), v.col(node));
    c.add(sigma * g.l, point, Vec<dim>::Zero());
    const Vec<dim> t = unit_vector<dim>(c.slope(sigma * g.l), "the string's tangent at the heap");
    c.v[c.n - 1] = -sigma * g.w * t;  // v⁺ = −ṡ0 t at a fixed point, ṡ0 = σ w
    g.e = sigma * t;
    g.position = point;
    return g;
  }
  if (links >= 2) {
    c.add(-2 * sigma * h, x.col(node + 2 * step), v.col(node + 2 * step));
    g.curvature = (x.col(node + 2 * step) - 2 * x.col(node + step) + x.col(node)) / (h * h);
  }
  if (links >= 1) {
    c.add(-sigma * h, x.col(node + step), v.col(node + step));
    c.add(0, x.col(node), v.col(node));
    if (links == 1) {  // one full link left: the curve keeps the second derivative x'' it last had
      g.curvature = last_curvature;
      c.add(sigma * h, Vec<dim>(2 * x.col(node) - x.col(node + step) + h * h * g.curvature),
            Vec<dim>(2 * v.col(node) - v.col(node + step)));
    }
  } else {  // no full link left: straight on along the kept direction, every point at v_k
    c.add(0, x.col(node), v.col(node));
    c.add(sigma * h, Vec<dim>(x.col(node) + h * last_direction), v.col(node));
  }
  const Vec<dim>& n = normal;
  const Vec<dim> e_last = unit_vector<dim>(Vec<dim>(sigma * c.slope(0)), "the link next to the heap");
  if (!(n.dot(e_last) < -kGrazing)) throw RecoverableError(not_meeting_plane(n.dot(e_last), node));
  double t = sigma * n.dot(point - x.col(node)) / n.dot(e_last);  // the last link's crossing
  // Converged when the step is below 1e-14 h, or at the round-off of the curve: Newton no longer
  // halves a step already below 1e-9 h. The curve is extrapolated past the end node when an accepted
  // step carries the contact beyond the insertion threshold (the root is then found inside the step),
  // and its round-off grows with the distance: 2.5 h out, steps of 1e-16 m against a test of 1e-16 m
  // never passed, and a pick-up from a table failed at an accepted state whenever its output times
  // gave it such a step (output.interval = 0.01 s, not 0.001 s).
  bool converged = false;
  double previous = INFINITY;
  for (int it = 0; it < 30 && !converged; ++it) {
    const double dt = -n.dot(c.position(t) - point) / n.dot(c.slope(t));
    t += dt;
    converged = std::abs(dt) <= 1e-14 * h || (std::abs(dt) <= 1e-9 * h && std::abs(dt) > 0.5 * previous);
    previous = std::abs(dt);
  }
  if (!converged) throw RecoverableError(fmt::format("the string near node {} does not meet the heap's plane", node));
  g.l = sigma * t;
  if (!(g.l > 1e-9 * h) || !std::isfinite(g.l)) throw RecoverableError(fmt::format("node {} has gone through the heap's plane", node));
  const Vec<dim> slope = c.slope(t);
  g.e = sigma * unit_vector<dim>(slope, "the string's tangent at the heap");
  if (!(n.dot(g.e) < -kGrazing)) throw RecoverableError(not_meeting_plane(n.dot(g.e), node));
  g.w = -sigma * n.dot(c.velocity(t)) / n.dot(slope);  // l = σ (s0 − s_k), ṡ0 = −n·ẋ(s0) / n·x'(s0)
  g.position = c.position(t);
  return g;
}
/// The full links the curve to the front may use (heap_geometry's `links`) at the end node `node` of arc `arc`
/// (the heap after it when `after`): the arc's links from the end node inwards up to the first slack one (slack =
/// "allow", docs/model.md §9 "Slack next to a front"): a slack link's nodes are not h apart along the string, and a
/// curve through them at material spacing h is not the string.
template <int dim>
int curve_links(const StringModel<dim>& model, int arc, int node, bool after) {
  const int links = model.arcs()[static_cast<std::size_t>(arc)].num_links();
  const int step = after ? -1 : 1;
  for (int taut = 0; taut < std::min(links, 2); ++taut)  // heap_geometry reads at most two
    if (model.link_slack(std::min(node + taut * step, node + (taut + 1) * step))) return taut;
  return links;
}
}  // namespace

template <int dim>
void check_heap_dissipation(const HeapSpec<dim>& spec, const std::string& name) {
  check_heap_dissipation(0, spec.side == HeapSpec<dim>::Side::kAfter, spec.pot, spec.dissipation, FrontKeys(name));
}

template <int dim>
HeapFront<dim>::HeapFront(const HeapSpec<dim>& spec)
    : after_(spec.side == HeapSpec<dim>::Side::kAfter), s0_(spec.s0), point_(spec.point), pot_(spec.pot) {
  this->dissipation = spec.dissipation;
  this->expected_s0 = spec.s0;
  if (spec.plane_normal) {
    on_plane_ = true;
    plane_surface_ = spec.plane_surface;
    normal_ = *spec.plane_normal;  // checked and made unit in cut(), after the layout's own checks
  }
}

template <int dim>
void HeapFront<dim>::trim(FrontLayout& layout) const {
  // The partial link starts in [h/2, 3h/2) (up to 1e-9 h), inside the thresholds by about kCrossingHysteresis·h.
  const double h = this->m_.h;
  const int n = this->m_.n;
  if (!after_)
    layout.first = std::min(n - 1, static_cast<int>(std::ceil((s0_ + 0.5 * h) / h - 1e-9)));
  else
    layout.last = std::max(layout.first, static_cast<int>(std::floor((s0_ - 0.5 * h) / h + 1e-9)));
}

template <int dim>
void HeapFront<dim>::cut(FrontLayout& layout) {
  this->arc_minus = after_ ? layout.arc : -1;
  this->arc_plus = after_ ? -1 : layout.arc;
  if (on_plane_) {
    std::string shown = "[";
    for (int d = 0; d < dim; ++d) shown += fmt::format("{}{}", d ? ", " : "", normal_[d]);
    check_plane_normal(normal_, shown + "]");
    const double norm = normal_.norm();
    normal_ = std::isfinite(norm) ? Vec<dim>(normal_ / norm) : Vec<dim>(normal_.stableNormalized());
    // An arc with no full link next to the heap takes the direction of its partial link from the
    // initial shape (initialize()).
  }
}

template <int dim>
typename HeapFront<dim>::End HeapFront<dim>::end(const StringModel<dim>& model) const {
  End e;
  e.arc = after_ ? this->arc_minus : this->arc_plus;
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(e.arc)];
  e.node = after_ ? arc.last : arc.first;
  e.inner = after_ ? e.node - 1 : e.node + 1;
  e.outer = after_ ? e.node + 1 : e.node - 1;
  e.removable = arc.last > arc.first && !model.is_prescribed(e.node);
  // A node comes out whole only if the front then stays inside the string (s0 = s_outer ± h/2).
  e.insertable = after_ ? e.outer <= this->m_.n - 2 : e.outer >= 1;
  return e;
}

template <int dim>
void HeapFront<dim>::initialize(StringModel<dim>& model) {
  if (pot_ && !on_plane_) {  // a pinned pot's mouth: the tangent at the front of the initial string
    const End e = end(model);
    const int links = model.arcs()[static_cast<std::size_t>(e.arc)].num_links();
    const HeapGeometry<dim> geo = heap_geometry<dim>(model.x(), model.v(), false, point_, normal_, last_direction_,
                                                     last_curvature_, e.node, after_, links, this->m_.h);
    pot_direction_ = -geo.e;
  }
  if (!on_plane_) return;
  const End e = end(model);
  if (model.arcs()[static_cast<std::size_t>(e.arc)].num_links() == 0) {
    // No full link: the string runs straight from the end node to the heap point (the direction
    // the front keeps until a node comes out).
    const Vec<dim> d = point_ - model.x().col(e.node);
    if (!(d.norm() > 1e-9 * this->m_.h))
      throw InputError(fmt::format("the initial shape does not fit the heap on the plane: node {} lies on the heap "
                                   "point, so the string's direction there is undefined",
                                   e.node));
    last_direction_ = d.normalized();
    const double height = normal_.dot(model.x().col(e.node) - point_);
    if (height < 0)
      throw InputError(fmt::format("the normal of the heap's plane must point to the string's side: node {} is "
                                   "{:.6g} m from the plane along it",
                                   e.node, height));
    return;
  }
  const double height = normal_.dot(model.x().col(e.inner) - point_);
  if (height < 0)  // on the plane itself: the grazing check says more
    throw InputError(fmt::format("the normal of the heap's plane must point to the string's side: node {} is "
                                 "{:.6g} m from the plane along it",
                                 e.inner, height));
  // The front on the plane is where the curve through the last three nodes before it meets the plane
  // (heap_geometry). Where the initial shape turns at the middle one of them (a corner of a polyline
  // within two links of the heap on a coarse mesh), that curve bends away from the last link and meets
  // the plane elsewhere: the tracker would refuse the front's place with "place the heap point at s0",
  // which it is (chain_into_heap_on_table.toml on 5 nodes: s0 = 0.859 m for 1 m, its corner at node 2).
  // Refused here with that cause.
  const int links = model.arcs()[static_cast<std::size_t>(e.arc)].num_links();
  if (links < 2) return;
  const int step = after_ ? -1 : 1, node = e.node;
  const Vec<dim> d1 = model.x().col(node + step) - model.x().col(node + 2 * step);
  const Vec<dim> d0 = model.x().col(node) - model.x().col(node + step);
  const double turn = std::acos(std::clamp(d1.normalized().dot(d0.normalized()), -1.0, 1.0));
  try {
    const HeapGeometry<dim> geo = heap_geometry<dim>(model.x(), model.v(), true, point_, normal_, last_direction_,
                                                     last_curvature_, node, after_, links, this->m_.h);
    const double sk = model.chain().node_coordinate(node), s0 = after_ ? sk + geo.l : sk - geo.l;
    if (std::abs(s0 - this->expected_s0) <= std::max(1e-6 * model.chain().length(), 0.1 * this->m_.h)) return;
    if (!(turn > 0.1)) return;  // the tracker's own message (a straight end: the heap point is elsewhere)
    throw InputError(fmt::format(
        "the heap front on the plane is found where the curve through the last three nodes before it (nodes {}, "
        "{}, {}) meets the plane, and the initial shape turns by {:.3g} degrees at node {} (links of h = {:.6g} m): "
        "that curve puts the front at s0 = {:.9g} m, not at s0 = {:.9g} m; allowed a string that runs straight "
        "over its last two links before the heap: more nodes (string.nodes), or the corner further from the heap",
        node + 2 * step, node + step, node, turn * 180 / kPi, node + step, this->m_.h, s0, this->expected_s0));
  } catch (const RecoverableError&) {
    return;  // the tracker's refresh says what is wrong
  }
}

template <int dim>
void HeapFront<dim>::evaluate(const StringModel<dim>& model, FrontState<dim>& s, Eigen::VectorXd& mass,
                              Points<dim>& force) {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  const double h = this->m_.h, lambda = this->m_.lambda;
  const End e_ = end(model);
  const int node = e_.node;
  // The string from the end node to the front (docs/shocks.md): its material length l, the tangent e
  // at the front (from the arc into the heap), the front point and w = dl/dt, the rate at which the
  // arc gains material (w < 0: it runs into the heap).
  const int links = held_links_ >= 0 ? std::min(held_links_, model.arcs()[static_cast<std::size_t>(e_.arc)].num_links())
                                     : curve_links(model, e_.arc, node, after_);
  last_links_ = links;
  const HeapGeometry<dim> geo =
      heap_geometry<dim>(x, v, on_plane_, point_, normal_, last_direction_, last_curvature_, node, after_, links, h);
  const double l = geo.l, w = geo.w;
  s.direction = geo.e;
  s.position = geo.position;
  if (on_plane_) {
    // kept for when crossings leave the arc with one full link (its curvature) or none (its direction)
    if (links > 0) {
      last_direction_ = geo.e;
      last_curvature_ = geo.curvature;
    }
    for (const ArcRange& arc : model.arcs())
      for (int i = arc.first; i <= arc.last && !plane_surface_; ++i)
        if (normal_.dot(x.col(i) - point_) < 0)
          throw RecoverableError(fmt::format("node {} has gone through the heap's plane away from the contact", i));
  }
  const Vec<dim> e = s.direction;
  const Vec<dim> v_end = v.col(node);
  s.inflow = w;
  const double sk = model.chain().node_coordinate(node);
  s.s0 = after_ ? sk + l : sk - l;
  s.s0_dot = after_ ? w : -w;
  // The jump conditions: the arc's end tension (on the − side of the front when the heap holds s > s0),
  // the internal shock at the contact, the reaction of the heap's support and the power exchanged
  // with the heap. The end node carries the partial link, so its mass changes at λ w: d(½ m v²)/dt
  // gains ½ λ w |v|², and the front force τ e works at τ e·v. The shock dissipates f λ |w|³ (none for a pot's
  // f < 0, jump::heap_shock_power); the rest is exchanged with the heap (−½ λ w³ for a string moving along
  // itself, as the paper's W*; −(½ + f) λ w³ for a pot's f < 0).
  // Momentum: the heap is at rest, so the supports give d(m v)/dt − (other forces) = τ e + λ w v.
  const double tau = jump::end_tension(this->dissipation, lambda, s.s0_dot, after_ ? -1 : +1);
  s.l_minus = after_ ? l : 0;
  s.l_plus = after_ ? 0 : l;
  s.tension_minus = after_ ? tau : 0;
  s.tension_plus = after_ ? 0 : tau;
  s.power_shock = jump::heap_shock_power(this->dissipation, lambda, s.s0_dot);  // 0 for a pot's f < 0
  s.power_heap = jump::heap_power<dim>(tau, e, v_end, lambda, w, s.power_shock);
  s.reaction = jump::heap_reaction<dim>(tau, e, v_end, lambda, w);
  s.heap = true;
  s.plane_normal = on_plane_ ? normal_ : Vec<dim>::Zero();
  partial_mid_ = geo.curve.position(0.5 * (after_ ? l : -l));
  mass[node] += lambda * l;
  force.col(node) += tau * e;
}

template <int dim>
std::vector<int> HeapFront<dim>::stencil(const StringModel<dim>& model) const {
  // heap_geometry reads the end node and up to two nodes into the arc (the interpolant near the front).
  const End e = end(model);
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(e.arc)];
  const int step = after_ ? -1 : 1;
  std::vector<int> nodes;
  for (int k = 0, i = e.node; k < 3 && i >= arc.first && i <= arc.last; ++k, i += step)
    if (!model.is_prescribed(i)) nodes.push_back(i);
  return nodes;
}

template <int dim>
std::optional<double> HeapFront<dim>::tension_at(const StringModel<dim>& model, const FrontState<dim>& s,
                                                 int node) const {
  if (end(model).node == node) return after_ ? s.tension_minus : s.tension_plus;
  return std::nullopt;
}

template <int dim>
double HeapFront<dim>::held_mass(const FrontState<dim>& s) const {
  return this->m_.lambda * (after_ ? this->m_.ell - s.s0 : s.s0);
}

template <int dim>
void HeapFront<dim>::add_held_moment_rate(const FrontState<dim>& s, Vec<dim>& rate) const {
  rate -= this->m_.lambda * s.inflow * s.position;
}

template <int dim>
void HeapFront<dim>::add_held_moment(const FrontState<dim>& s, double before, Vec<dim>& moment) const {
  moment += (held_mass(s) - before) * s.position;
}

template <int dim>
void HeapFront<dim>::add_support(const FrontState<dim>& s, const Vec<dim>& g, double& mass, Vec<dim>& support) const {
  const double heap = held_mass(s);
  mass += heap;
  support += s.reaction - heap * g;  // the heap's support holds its weight too
}

template <int dim>
double HeapFront<dim>::potential_moment(const StringModel<dim>& model, const FrontState<dim>& s,
                                        const Vec<dim>& g) const {
  const double l = after_ ? s.l_minus : s.l_plus;
  return this->m_.lambda * l * g.dot(partial_mid_ - model.x().col(end(model).node));
}

template <int dim>
void HeapFront<dim>::crossings(const StringModel<dim>& model, const FrontState<dim>& s, double* g) const {
  const End e = end(model);
  const double h = this->m_.h;
  const double l = after_ ? s.l_minus : s.l_plus;
  g[0] = l - (e.removable ? kRemove : kLastPartial) * h;
  // When no node can come out any more, the event is the heap running empty: its content (ℓ − s0 or
  // s0) falling below the round-off of s0 (a sum of link lengths and a projection). A heap that
  // starts empty and fills, as the falling chain's, starts at content ±1 ulp: at 3,300 and 6,400
  // nodes that sign flipped at the first steps and stopped the run at t ≈ 0.
  const double content = after_ ? this->m_.ell - s.s0 : s.s0;
  g[1] = e.insertable ? l - kInsert * h
                      : -content - kEmptyHeap * this->m_.ell + (model.has_bends() ? kEmptyLinks * h : 0.0);
}

template <int dim>
EventAction HeapFront<dim>::cross(StringModel<dim>& model, const FrontState<dim>& /*state*/, int e0) {
  Points<dim>& x = model.x();
  Points<dim>& v = model.v();
  const End e = end(model);
  ArcRange& arc = model.arcs()[static_cast<std::size_t>(e.arc)];
  if (e0 != 0) {
    if (!e.removable)
      return {EventAction::Kind::kStop,
              fmt::format("the string has run into the heap: its last node is {:.3g} h from the heap point",
                          kLastPartial)};
    // The end node joins the heap; every other node keeps its position and velocity (samples of the
    // string, so the crossing adds no error to the state); the new end carries the string to the
    // front through the node before (its mass follows at the next refresh).
    (after_ ? arc.last : arc.first) = e.inner;
  } else {
    if (!e.insertable) return {EventAction::Kind::kStop, "the heap has run empty"};
    // A new node comes out at the material point s_k ± h of the string near the front (its
    // interpolant through the end nodes and the front), with the velocity there.
    const double h = this->m_.h;
    const HeapGeometry<dim> geo = heap_geometry<dim>(x, v, on_plane_, point_, normal_, last_direction_,
                                                     last_curvature_, e.node, after_, curve_links(model, e.arc, e.node, after_), h);
    // A pinned pot's node comes out through its mouth instead: on the line from the pot point along the mouth,
    // (l − h) from it, moving along it at w (docs/shocks.md, "A pot": the string leaving a pot that pushes
    // needs its direction there as well as its point).
    const double at = after_ ? h : -h;
    const bool mouth = pot_ && !on_plane_;
    x.col(e.outer) = mouth ? Vec<dim>(point_ + (geo.l - h) * pot_direction_) : geo.curve.position(at);
    v.col(e.outer) = mouth ? Vec<dim>(geo.w * pot_direction_) : geo.curve.velocity(at);
    (after_ ? arc.last : arc.first) = e.outer;
  }
  model.rebuild();
  model.refresh();
  return {EventAction::Kind::kTransfer, {}};
}

template class HeapFront<2>;
template class HeapFront<3>;
template void check_heap_dissipation<2>(const HeapSpec<2>&, const std::string&);
template void check_heap_dissipation<3>(const HeapSpec<3>&, const std::string&);

}  // namespace chainsim
