// Front tracking as a module of the one discrete string: see front_tracker.hpp.
#include "front_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

namespace {
/// A heap takes in an arc's end node when its partial link shrinks to kRemove·h and gives out a new
/// node when it grows to kInsert·h: the partial link stays in [h/2, 3h/2], away from zero length
/// (where its direction is undefined), widened by kHysteresis·h on either side. The initial layout
/// puts the partial link in [h/2, 3h/2) (up to 1e-9 h), and a crossing moves it by h, so that every
/// root function starts at least ~kHysteresis·h from zero. With the thresholds at exactly h/2 and
/// 3h/2, a front starting exactly h/2 past a node had a root function that was zero where the
/// integration starts, which ARKODE does not report: the falling chain from eta0 = 0.5 on 4, 6 and 10
/// nodes ran past it unseen and stalled. Crossing it at t = 0 instead left the partial link on the
/// other threshold with a front at rest, whose first steps move it by less than the round-off of
/// the partial link (1e-23 m against 1e-17 m): that sign noise gave the opposite crossing at
/// t = 1.5e-9 s (14 nodes). A band wider by a quarter link avoided both but used the end interpolant
/// further from the nodes and cost the swinging sliding chain its convergence (order -1.08).
constexpr double kHysteresis = 1e-6;
constexpr double kRemove = 0.5 - kHysteresis, kInsert = 1.5 + kHysteresis;
/// The last node of an arc cannot be taken in; the run stops when its partial link is this short.
constexpr double kLastPartial = 1e-3;
/// A heap whose content is below this fraction of the string's length (64 ε) is empty.
constexpr double kEmptyHeap = 64 * std::numeric_limits<double>::epsilon();
/// A string meeting a plane at less than this cosine between its tangent and the plane's normal
/// runs along the plane: the contact point is then ill-defined and the run stops.
constexpr double kGrazing = 1e-3;

template <int dim>
Vec<dim> unit(const Vec<dim>& d, const char* what) {
  const double n = d.norm();
  if (!(n > 0) || !std::isfinite(n)) throw RecoverableError(fmt::format("{} has zero length", what));
  return d / n;
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
HeapGeometry<dim> heap_geometry(const Points<dim>& x, const Points<dim>& v, const typename FrontTracker<dim>::Front& front,
                                int node, bool after, int links, double h) {
  const bool on_plane = front.on_plane;
  const Vec<dim>& point = front.point;
  const Vec<dim>& normal = front.normal;
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
    const Vec<dim> t = unit<dim>(c.slope(sigma * g.l), "the string's tangent at the heap");
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
      g.curvature = front.last_curvature;
      c.add(sigma * h, Vec<dim>(2 * x.col(node) - x.col(node + step) + h * h * g.curvature),
            Vec<dim>(2 * v.col(node) - v.col(node + step)));
    }
  } else {  // no full link left: straight on along the kept direction, every point at v_k
    c.add(0, x.col(node), v.col(node));
    c.add(sigma * h, Vec<dim>(x.col(node) + h * front.last_direction), v.col(node));
  }
  const Vec<dim>& n = normal;
  const Vec<dim> e_last = unit<dim>(Vec<dim>(sigma * c.slope(0)), "the link next to the heap");
  if (!(n.dot(e_last) < -kGrazing))
    throw RecoverableError(
        fmt::format("the string meets the heap's plane at a grazing angle (n·t = {:.3g} at node {})", n.dot(e_last), node));
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
  g.e = sigma * unit<dim>(slope, "the string's tangent at the heap");
  if (!(n.dot(g.e) < -kGrazing))
    throw RecoverableError(
        fmt::format("the string meets the heap's plane at a grazing angle (n·t = {:.3g} at node {})", n.dot(g.e), node));
  g.w = -sigma * n.dot(c.velocity(t)) / n.dot(slope);  // l = σ (s0 − s_k), ṡ0 = −n·ẋ(s0) / n·x'(s0)
  g.position = c.position(t);
  return g;
}
}  // namespace

template <int dim>
FrontTracker<dim>::FrontTracker(std::vector<HeapSpec<dim>> heaps, std::optional<FoldSpec> fold,
                                const FrontOptions& options)
    : heap_specs_(std::move(heaps)), fold_spec_(fold), options_(options) {}

template <int dim>
int FrontTracker<dim>::num_folds() const {
  int n = 0;
  for (const Front& front : fronts_) n += front.kind == FrontKind::kFold ? 1 : 0;
  return n;
}

template <int dim>
std::vector<ArcRange> FrontTracker<dim>::initial_arcs(const Chain<dim>& chain) {
  const int L = chain.num_links();
  h_ = chain.link_length(0);
  for (int j = 1; j < L; ++j)
    if (std::abs(chain.link_length(j) - h_) > 1e-12 * h_)
      throw InputError("a string with fronts needs links of equal material length");
  if (L < 2) throw InputError(fmt::format("a string with fronts needs at least 2 links, got {}", L));
  lambda_ = chain.density();
  n_ = chain.num_nodes();
  ell_ = chain.length();
  const double ell = ell_;
  // 1. Fronts in order of s: heap before, fold, heap after.
  const HeapSpec<dim>* before = nullptr;
  const HeapSpec<dim>* after = nullptr;
  for (auto& heap : heap_specs_) {
    require_in_range("heap.dissipation", heap.dissipation, 0.0, 1.0);
    if (std::abs(heap.s0 - ell) <= 1e-12 * ell) heap.s0 = ell;  // ℓ is a sum of link lengths
    if (std::abs(heap.s0) <= 1e-12 * ell) heap.s0 = 0;
    if (heap.side == HeapSpec<dim>::Side::kAfter)
      require_in_range("heap.s0", heap.s0, 0.0, ell, Bound::kOpen, Bound::kClosed);
    else
      require_in_range("heap.s0", heap.s0, 0.0, ell, Bound::kClosed, Bound::kOpen);
    auto& slot = heap.side == HeapSpec<dim>::Side::kBefore ? before : after;
    if (slot) throw InputError("at most one heap on each side of the string");
    slot = &heap;
  }
  const std::optional<FoldSpec>& fold = fold_spec_;
  if (fold) {
    require_in_range("fold.dissipation", fold->dissipation, 0.0, 1.0);
    require_in_range("fold.s0", fold->s0, 0.0, ell, Bound::kClosed, Bound::kOpen);
    if ((before && fold->s0 <= before->s0) || (after && fold->s0 >= after->s0))
      throw InputError("the fold must lie between the heaps");
  }
  if (before && after && after->s0 - before->s0 < 2 * h_)
    throw InputError("the heaps are less than two links apart: use more nodes");
  // 2. Arcs: node ranges between the fronts.
  std::vector<ArcRange> arcs;
  auto node_at_or_before = [&](double s) { return std::clamp(static_cast<int>(std::floor(s / h_ + 1e-9)), 0, n_ - 1); };
  int first = 0, last = n_ - 1;
  // Each heap's partial link starts in [h/2, 3h/2) (up to 1e-9 h), inside the thresholds by about
  // kHysteresis·h.
  if (before)
    first = std::min(n_ - 1, static_cast<int>(std::ceil((before->s0 + 0.5 * h_) / h_ - 1e-9)));
  if (after)
    last = std::max(first, static_cast<int>(std::floor((after->s0 - 0.5 * h_) / h_ + 1e-9)));
  if (fold) {
    const int a = node_at_or_before(fold->s0);
    if (a < first || a + 1 > last) throw InputError("the fold must lie inside the moving part of the string");
    arcs.push_back({first, a});
    arcs.push_back({a + 1, last});
  } else {
    arcs.push_back({first, last});
  }
  const int last_arc = static_cast<int>(arcs.size()) - 1;
  auto heap_front = [&](const HeapSpec<dim>& spec, int arc_minus, int arc_plus) {
    Front front;
    front.dissipation = spec.dissipation;
    front.point = spec.point;
    front.arc_minus = arc_minus;
    front.arc_plus = arc_plus;
    if (spec.plane_normal) {
      const double norm = spec.plane_normal->norm();
      if (!(norm > 0) || !std::isfinite(norm)) throw InputError("the normal of a heap's plane must be a nonzero vector");
      front.on_plane = true;
      front.normal = *spec.plane_normal / norm;
      // An arc with no full link next to the heap takes the direction of its partial link from the
      // initial shape (initialize()).
    }
    return front;
  };
  fronts_.clear();
  expected_s0_.clear();
  if (before) {
    fronts_.push_back(heap_front(*before, -1, 0));
    expected_s0_.push_back(before->s0);
  }
  if (fold) {
    Front front;
    front.kind = FrontKind::kFold;
    front.dissipation = fold->dissipation;
    front.arc_minus = 0;
    front.arc_plus = 1;
    fronts_.push_back(front);
    expected_s0_.push_back(fold->s0);
  }
  if (after) {
    fronts_.push_back(heap_front(*after, last_arc, -1));
    expected_s0_.push_back(after->s0);
  }
  for (const auto& stop : options_.stop_at)
    if (stop.front < 0 || stop.front >= static_cast<int>(fronts_.size()))
      throw InputError(fmt::format("stop condition on front {}: the string has {} fronts", stop.front, fronts_.size()));
  fs_.assign(fronts_.size(), FrontState<dim>{});
  fold_chord_.assign(fronts_.size(), 0.0);
  partial_mid_.assign(fronts_.size(), Vec<dim>::Zero());
  return arcs;
}

template <int dim>
void FrontTracker<dim>::initialize(StringModel<dim>& model) {
  for (Front& front : fronts_) {
    if (!front.on_plane) continue;
    const HeapEnd end = heap_end(model, front);
    if (model.arcs()[static_cast<std::size_t>(end.arc)].num_links() == 0) {
      // No full link: the string runs straight from the end node to the heap point (the direction
      // the front keeps until a node comes out).
      const Vec<dim> d = front.point - model.x().col(end.node);
      if (!(d.norm() > 1e-9 * h_))
        throw InputError(fmt::format("the initial shape does not fit the heap on the plane: node {} lies on the heap "
                                     "point, so the string's direction there is undefined",
                                     end.node));
      front.last_direction = d.normalized();
      const double height = front.normal.dot(model.x().col(end.node) - front.point);
      if (height < 0)
        throw InputError(fmt::format("the normal of the heap's plane must point to the string's side: node {} is "
                                     "{:.6g} m from the plane along it",
                                     end.node, height));
      continue;
    }
    const int inner = end.inner;
    const double height = front.normal.dot(model.x().col(inner) - front.point);
    if (height < 0)  // on the plane itself: the grazing check below says more
      throw InputError(fmt::format("the normal of the heap's plane must point to the string's side: node {} is "
                                   "{:.6g} m from the plane along it",
                                   inner, height));
  }
  try {
    model.refresh();
  } catch (const RecoverableError& e) {
    throw InputError(fmt::format("the initial shape does not fit the fronts: {}", e.what()));
  }
  // A front is where the links put it: a partial link is straight, so on a curved shape the front
  // lies off s0 by O(κ h²). That is accepted up to a tenth of a link; the masses follow the geometry.
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (std::abs(fs_[k].s0 - expected_s0_[k]) > std::max(1e-6 * ell_, 0.1 * h_))
      throw InputError(fmt::format(
          "the {} front is meant to be at s0 = {:.9g} m but the initial shape puts it at s0 = {:.9g} m: "
          "place the {} at the string's material point s0",
          fronts_[k].kind == FrontKind::kHeap ? "heap" : "fold", expected_s0_[k], fs_[k].s0,
          fronts_[k].kind == FrontKind::kHeap ? "heap point" : "fold"));
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kFold && fs_[k].opening > kMaxFoldOpeningDeg * kPi / 180)
      throw InputError(fold_opened_message(k));
  heap_moment0_.setZero();
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kHeap) heap_moment0_ += heap_mass(k) * fs_[k].position;
}

template <int dim>
typename FrontTracker<dim>::HeapEnd FrontTracker<dim>::heap_end(const StringModel<dim>& model, const Front& front) const {
  HeapEnd end;
  end.after = front.arc_plus < 0;
  end.arc = end.after ? front.arc_minus : front.arc_plus;
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(end.arc)];
  end.node = end.after ? arc.last : arc.first;
  end.inner = end.after ? end.node - 1 : end.node + 1;
  end.outer = end.after ? end.node + 1 : end.node - 1;
  end.removable = arc.last > arc.first && !model.is_prescribed(end.node);
  // A node comes out whole only if the front then stays inside the string (s0 = s_outer ± h/2).
  end.insertable = end.after ? end.outer <= n_ - 2 : end.outer >= 1;
  return end;
}

template <int dim>
std::string FrontTracker<dim>::fold_opened_message(std::size_t front) const {
  return fmt::format(
      "the fold at s0 = {:.6g} m has opened: its arms leave it {:.3g} degrees from antiparallel (a tight bight allows "
      "at most {:g}; a dissipative fold needs both arms along one line, and a bight that opens, as in a folded chain "
      "whose ends are apart, is resolved by the string solver without [effects.fold]: docs/shocks.md)",
      fs_[front].s0, fs_[front].opening * 180 / kPi, kMaxFoldOpeningDeg);
}

template <int dim>
std::string FrontTracker<dim>::fold_apart_message(const StringModel<dim>& model, std::size_t front, double t) const {
  const FrontState<dim>& s = fs_[front];
  const int a = model.arcs()[static_cast<std::size_t>(fronts_[front].arc_minus)].last;
  const int b = model.arcs()[static_cast<std::size_t>(fronts_[front].arc_plus)].first;
  // The arms at the fold: arc A's end link and arc B's first link (an arc without a full link: its
  // partial link to the fold point x0), on one line for a tight fold; and the transverse force the
  // momentum balance needs there for dissipation f: F0 = f λ ṡ0 |ṡ0| (t⁺ + t⁻) (docs/shocks.md).
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(fronts_[front].arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(fronts_[front].arc_plus)];
  const Points<dim>& x = model.x();
  const Vec<dim> t_minus =
      (A.num_links() > 0 ? Vec<dim>(x.col(a) - x.col(a - 1)) : Vec<dim>(s.position - x.col(a))).normalized();
  const Vec<dim> t_plus =
      (B.num_links() > 0 ? Vec<dim>(x.col(b + 1) - x.col(b)) : Vec<dim>(x.col(b) - s.position)).normalized();
  const double angle = std::acos(std::clamp(-t_minus.dot(t_plus), -1.0, 1.0));
  const double missing = fronts_[front].dissipation * lambda_ * s.s0_dot * s.s0_dot * (t_plus + t_minus).norm();
  return fmt::format(
      "the fold at s0 = {:.6g} m has come apart at t = {:.9g} s: the ends of its folded link, nodes {} and {} (s = {:.6g} "
      "and {:.6g} m), are {:.5g} h apart (h = {:.6g} m): the link's material no longer reaches across, and a tight fold "
      "(arms within {:g} degrees of antiparallel) needs at most {:.5g} h to cross a node; its arms leave it {:.3g} degrees from antiparallel, ds0/dt = {:.4g} m/s, tension {:.4g} N before the fold and {:.4g} N after it. "
      "Across a kink whose arms are not antiparallel the momentum balance needs a transverse force f lambda "
      "ds0/dt |ds0/dt| |t+ + t-| = {:.3g} N at the fold, zero only for f = 0, and the fold has none: a tight fold "
      "cannot form here. For f = 0 run the scene without [effects.fold] (the string resolves the kink); for f > 0 a "
      "tight fold needs its arms on one line (docs/shocks.md, \"A fold whose arms turn apart\")",
      s.s0, t, a, b, model.chain().node_coordinate(a), model.chain().node_coordinate(b), fold_chord_[front], h_,
      kMaxFoldOpeningDeg, max_fold_chord(), angle * 180 / kPi, s.s0_dot, s.tension_minus, s.tension_plus, missing);
}

template <int dim>
void FrontTracker<dim>::add_mass_and_forces(const StringModel<dim>& model, Eigen::VectorXd& mass, Points<dim>& force) {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  const Chain<dim>& chain = model.chain();
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    Front& front = fronts_[k];
    FrontState<dim>& s = fs_[k];
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(model, front);
      const bool after = end.after;
      const int node = end.node;
      // The string from the end node to the front (docs/shocks.md): its material length l, the
      // tangent e at the front (from the arc into the heap), the front point and w = dl/dt, the rate
      // at which the arc gains material (w < 0: it runs into the heap).
      const int links = model.arcs()[static_cast<std::size_t>(end.arc)].num_links();
      const HeapGeometry<dim> geo = heap_geometry<dim>(x, v, front, node, after, links, h_);
      const double l = geo.l, w = geo.w;
      s.direction = geo.e;
      s.position = geo.position;
      if (front.on_plane) {
        // kept for when crossings leave the arc with one full link (its curvature) or none (its direction)
        if (links > 0) {
          front.last_direction = geo.e;
          front.last_curvature = geo.curvature;
        }
        for (const ArcRange& arc : model.arcs())
          for (int i = arc.first; i <= arc.last; ++i)
            if (front.normal.dot(x.col(i) - front.point) < 0)
              throw RecoverableError(fmt::format("node {} has gone through the heap's plane away from the contact", i));
      }
      const Vec<dim> e = s.direction;
      const Vec<dim> v_end = v.col(node);
      s.inflow = w;
      const double tau = lambda_ * w * w * (1 + front.dissipation * jump::sign(w));
      const double sk = chain.node_coordinate(node);
      s.s0 = after ? sk + l : sk - l;
      s.s0_dot = after ? w : -w;
      s.l_minus = after ? l : 0;
      s.l_plus = after ? 0 : l;
      s.tension_minus = after ? tau : 0;
      s.tension_plus = after ? 0 : tau;
      // The end node carries the partial link, so its mass changes at λ w: d(½ m v²)/dt gains
      // ½ λ w |v|², and the front force τ e works at τ e·v. The shock dissipates f λ |w|³; the rest
      // is exchanged with the heap (−½ λ w³ for a string moving along itself, as the paper's W*).
      s.power_shock = -front.dissipation * lambda_ * std::abs(w) * w * w;
      s.power_heap = tau * e.dot(v_end) + 0.5 * lambda_ * w * v_end.squaredNorm() - s.power_shock;
      // Momentum: the heap is at rest, so the supports give d(m v)/dt − (other forces) = τ e + λ w v.
      s.reaction = tau * e + lambda_ * w * v_end;
      s.heap = true;
      s.plane_normal = front.on_plane ? front.normal : Vec<dim>::Zero();
      partial_mid_[k] = geo.curve.position(0.5 * (after ? l : -l));
      mass[node] += lambda_ * l;
      force.col(node) += tau * e;
    } else {
      const ArcRange& A = model.arcs()[static_cast<std::size_t>(front.arc_minus)];
      const ArcRange& B = model.arcs()[static_cast<std::size_t>(front.arc_plus)];
      const int a = A.last, b = B.first;
      // The fold direction e: the bisector of arc A's end link t_A and arc B's first link reversed
      // (−t_B), or the one of them that exists; with its rate ė, for the mass flux below.
      auto tangent = [&](int i, int j, const char* what, Vec<dim>& rate) -> Vec<dim> {  // of link i → j
        const Vec<dim> link = x.col(j) - x.col(i), link_rate = v.col(j) - v.col(i);
        const Vec<dim> t = unit<dim>(link, what);
        rate = (link_rate - t * t.dot(link_rate)) / link.norm();
        return t;
      };
      Vec<dim> tA_rate = Vec<dim>::Zero(), tB_rate = Vec<dim>::Zero();
      const bool has_A = A.num_links() > 0, has_B = B.num_links() > 0;
      if (!has_A && !has_B) throw InputError("a fold needs at least one full link next to it");
      const Vec<dim> tA = has_A ? tangent(a - 1, a, "arc A's end link", tA_rate) : Vec<dim>::Zero();
      const Vec<dim> tB = has_B ? tangent(b, b + 1, "arc B's first link", tB_rate) : Vec<dim>::Zero();
      const Vec<dim> d = tA - tB, d_rate = tA_rate - tB_rate;
      const Vec<dim> e = unit<dim>(d, "the fold direction");
      const Vec<dim> e_rate = (d_rate - e * e.dot(d_rate)) / d.norm();
      s.opening = has_A && has_B ? std::acos(std::clamp(-tA.dot(tB), -1.0, 1.0)) : 0.0;
      const double c = (x.col(b) - x.col(a)).dot(e);
      fold_chord_[k] = (x.col(b) - x.col(a)).norm() / h_;
      const double lA = 0.5 * (h_ + c), lB = 0.5 * (h_ - c);
      const double sd = 0.5 * (v.col(b) - v.col(a)).dot(e);
      const double sg = jump::sign(sd);
      s.direction = e;
      s.position = 0.5 * (x.col(a) + x.col(b)) + 0.5 * h_ * e;
      s.s0 = chain.node_coordinate(a) + lA;
      s.s0_dot = sd;
      s.l_minus = lA;
      s.l_plus = lB;
      s.tension_minus = lambda_ * sd * sd * (1 + front.dissipation * sg);
      s.tension_plus = lambda_ * sd * sd * (1 - front.dissipation * sg);
      s.power_shock = -2 * front.dissipation * lambda_ * std::abs(sd) * sd * sd;
      s.power_heap = 0;
      s.reaction.setZero();
      s.inflow = 0;
      mass[a] += lambda_ * lA;
      mass[b] += lambda_ * lB;
      // Material crosses from b to a at the rate l̇_A = ½ (u·e + (x_b − x_a)·ė), u = v_b − v_a, carrying
      // the momentum flux λ l̇_A u. For arms on one line (u = 2 ṡ0 e, ė = 0) that is 2 λ ṡ0² e = τ⁻ + τ⁺,
      // the paper's fold. Otherwise the remainder δ, shared equally by the two nodes, keeps momentum
      // exact, and the energy then balances with W_s = −2 f λ |ṡ0|³ exactly (docs/shocks.md).
      const Vec<dim> u = v.col(b) - v.col(a);
      const double lA_rate = 0.5 * (u.dot(e) + (x.col(b) - x.col(a)).dot(e_rate));
      const Vec<dim> delta = lambda_ * lA_rate * u - 2 * lambda_ * sd * sd * e;
      force.col(a) += s.tension_minus * e + 0.5 * delta;
      force.col(b) += s.tension_plus * e + 0.5 * delta;
    }
  }
  for (int i = 0; i < n_; ++i)
    if (model.in_arc(i) && !model.is_prescribed(i) && !(mass[i] > 1e-12 * lambda_ * h_))
      throw RecoverableError(fmt::format("node {} has lost its mass (a front overshot it)", i));
}

template <int dim>
std::optional<double> FrontTracker<dim>::front_tension_at(const StringModel<dim>& model, int node) const {
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    const Front& front = fronts_[k];
    const FrontState<dim>& s = fs_[k];
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(model, front);
      if (end.node == node) return end.after ? s.tension_minus : s.tension_plus;
    } else {
      if (model.arcs()[static_cast<std::size_t>(front.arc_minus)].last == node) return s.tension_minus;
      if (model.arcs()[static_cast<std::size_t>(front.arc_plus)].first == node) return s.tension_plus;
    }
  }
  return std::nullopt;
}

template <int dim>
void FrontTracker<dim>::ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const {
  // [ W_shocks | W_heaps | impulse | heap moment ]: the external forces on the string are the
  // string's (applied forces, prescribed nodes' reactions) plus the heaps' reactions.
  double w_shocks = 0, w_heaps = 0;
  Vec<dim> external = model.external_force(), heap_moment_rate = Vec<dim>::Zero();
  for (std::size_t k = 0; k < fs_.size(); ++k) {
    const FrontState<dim>& s = fs_[k];
    w_shocks += s.power_shock;
    w_heaps += s.power_heap;
    external += s.reaction;
    if (fronts_[k].kind == FrontKind::kHeap) heap_moment_rate -= lambda_ * s.inflow * s.position;
  }
  rates[0] = w_shocks;
  rates[1] = w_heaps;
  rates.template segment<dim>(2) = external;
  rates.template segment<dim>(2 + dim) = heap_moment_rate;
}

template <int dim>
Eigen::VectorXd FrontTracker<dim>::ledger_scale(double mass, double speed, double length) const {
  Eigen::VectorXd scale(num_ledgers());
  scale.head(2).setConstant(mass * speed * speed);
  scale.segment(2, dim).setConstant(mass * speed);
  scale.tail(dim).setConstant(mass * length);
  return scale;
}

template <int dim>
double FrontTracker<dim>::heap_mass(std::size_t k) const {
  const bool after = fronts_[k].arc_plus < 0;
  return lambda_ * (after ? ell_ - fs_[k].s0 : fs_[k].s0);
}

template <int dim>
double FrontTracker<dim>::potential_correction(const StringModel<dim>& model,
                                               const Eigen::Ref<const Eigen::VectorXd>& ledger) const {
  // The string's V lumps every mass on a node: a partial link of length l on its end node. The
  // potential energy counts it at its midpoint, and the heaps at their first moment.
  const Vec<dim> g = model.gravity();
  double first_moment = g.dot(heap_moment0_ + ledger.template segment<dim>(2 + dim));
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    const Front& front = fronts_[k];
    const FrontState<dim>& f = fs_[k];
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(model, front);
      const double l = end.after ? f.l_minus : f.l_plus;
      first_moment += lambda_ * l * g.dot(partial_mid_[k] - model.x().col(end.node));
    } else {
      const int a = model.arcs()[static_cast<std::size_t>(front.arc_minus)].last;
      const int b = model.arcs()[static_cast<std::size_t>(front.arc_plus)].first;
      first_moment += lambda_ * f.l_minus * g.dot(0.5 * (f.position - model.x().col(a))) +
                      lambda_ * f.l_plus * g.dot(0.5 * (f.position - model.x().col(b)));
    }
  }
  return -first_moment;
}

template <int dim>
void FrontTracker<dim>::fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
                             ModuleLedger<dim>& out) const {
  out.fronts = fs_;
  out.w_shocks = ledger[0];
  out.w_heaps = ledger[1];
  out.impulse = ledger.template segment<dim>(2);
  out.heap_moment = heap_moment0_ + ledger.template segment<dim>(2 + dim);
  out.w_remesh = w_remesh_;
  out.has_momentum_ledger = true;
  out.heap_mass = 0;
  out.support.setZero();
  const Vec<dim> g = model.gravity();
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    if (fronts_[k].kind != FrontKind::kHeap) continue;
    const double heap = heap_mass(k);
    out.heap_mass += heap;
    out.support += fs_[k].reaction - heap * g;  // the heap's support holds its weight too
  }
}

template <int dim>
void FrontTracker<dim>::events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const {
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    const Front& front = fronts_[k];
    const FrontState<dim>& s = fs_[k];
    double* gk = g.data() + 2 * k;
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(model, front);
      const double l = end.after ? s.l_minus : s.l_plus;
      gk[0] = l - (end.removable ? kRemove : kLastPartial) * h_;
      // When no node can come out any more, the event is the heap running empty: its content
      // (ℓ − s0 or s0) falling below the round-off of s0 (a sum of link lengths and a projection).
      // A heap that starts empty and fills, as the falling chain's, starts at content ±1 ulp: at
      // 3,300 and 6,400 nodes that sign flipped at the first steps and stopped the run at t ≈ 0.
      const double content = end.after ? ell_ - s.s0 : s.s0;
      gk[1] = end.insertable ? l - kInsert * h_ : -content - kEmptyHeap * ell_;
    } else {
      gk[0] = s.l_plus;   // the fold reaches arc B's first node
      gk[1] = s.l_minus;  // the fold reaches arc A's last node
    }
  }
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k) {
    const auto& stop = options_.stop_at[k];
    g[2 * static_cast<int>(fronts_.size()) + static_cast<int>(k)] = fs_[static_cast<std::size_t>(stop.front)].s0 - stop.s;
  }
  // Each fold: positive while its arms are within kMaxFoldOpeningDeg of antiparallel and its folded
  // link's material spans its chord.
  int q = 2 * static_cast<int>(fronts_.size()) + static_cast<int>(options_.stop_at.size());
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kFold)
      g[q++] = std::min(std::cos(fs_[k].opening) - std::cos(kMaxFoldOpeningDeg * kPi / 180),
                        max_fold_chord() - fold_chord_[k]);
}

template <int dim>
std::vector<int> FrontTracker<dim>::event_directions() const {
  std::vector<int> dirs;
  for (const Front& front : fronts_) {
    dirs.push_back(-1);
    dirs.push_back(front.kind == FrontKind::kHeap ? +1 : -1);
  }
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k) dirs.push_back(0);
  for (int k = 0; k < num_folds(); ++k) dirs.push_back(-1);
  return dirs;
}

template <int dim>
EventAction FrontTracker<dim>::handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                                             const std::vector<int>& found) {
  const int nf = static_cast<int>(fronts_.size());
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k)
    if (found[static_cast<std::size_t>(2 * nf) + k] != 0)
      return {EventAction::Kind::kStop,
              fmt::format("front {} reached s0 = {:.9g} m", options_.stop_at[k].front, options_.stop_at[k].s)};
  for (std::size_t k = 0, q = static_cast<std::size_t>(2 * nf) + options_.stop_at.size(); k < fronts_.size(); ++k) {
    if (fronts_[k].kind != FrontKind::kFold) continue;
    if (found[q++] == 0) continue;
    const bool apart = max_fold_chord() - fold_chord_[k] <=
                       std::cos(fs_[k].opening) - std::cos(kMaxFoldOpeningDeg * kPi / 180);
    return {EventAction::Kind::kStop, apart ? fold_apart_message(model, k, t) : fold_opened_message(k)};
  }
  // Energy, momentum and heap masses before, to book what the crossing changes.
  const double E_before = model.kinetic_energy() + model.potential_energy(ledger);
  const Vec<dim> p_before = model.momentum();
  std::vector<double> heap_before(fronts_.size());
  for (std::size_t k = 0; k < fronts_.size(); ++k) heap_before[k] = heap_mass(k);
  for (int f = 0; f < nf; ++f) {
    const int e0 = found[static_cast<std::size_t>(2 * f)], e1 = found[static_cast<std::size_t>(2 * f + 1)];
    if (e0 == 0 && e1 == 0) continue;
    const EventAction action = transfer(model, static_cast<std::size_t>(f), e0);
    if (action.kind == EventAction::Kind::kStop) return action;
    ++transfers_;
    break;  // one crossing per event; a simultaneous one is found again right after
  }
  // The new links are brought back to their lengths (a fold's arms are never exactly antiparallel
  // in the discrete state); the kinetic energy the crossing changes is booked.
  model.refresh();
  try {
    model.project(t);
  } catch (const NumericalError& e) {
    throw NumericalError(fmt::format("after a front crossing: {}", e.what()), t);
  }
  model.refresh();
  // The material a crossing moves between an arc and a heap (the front is re-drawn through the new
  // end node: O(h³) of material) goes with its momentum and is laid at the front; a heap crossing
  // also re-lumps the end's material on the nodes with their own velocities (the lumped momentum
  // changes by O(h²), what the lumped partial link missed, docs/shocks.md), and the projection
  // acts through fixed nodes. All of it is the supports' impulse; the energy it changes is W_remesh.
  ledger.template segment<dim>(2) += model.momentum() - p_before;
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kHeap)
      ledger.template segment<dim>(2 + dim) += (heap_mass(k) - heap_before[k]) * fs_[k].position;
  w_remesh_ += model.kinetic_energy() + model.potential_energy(ledger) - E_before;
  return {EventAction::Kind::kTransfer, {}};
}

template <int dim>
EventAction FrontTracker<dim>::transfer(StringModel<dim>& model, std::size_t f, int e0) {
  Front& front = fronts_[f];
  Points<dim>& x = model.x();
  Points<dim>& v = model.v();
  if (front.kind == FrontKind::kHeap) {
    const HeapEnd end = heap_end(model, front);
    ArcRange& arc = model.arcs()[static_cast<std::size_t>(end.arc)];
    const int node = end.node, inner = end.inner, outer = end.outer;
    if (e0 != 0) {
      if (!end.removable)
        return {EventAction::Kind::kStop,
                fmt::format("the string has run into the heap: its last node is {:.3g} h from the heap point",
                            kLastPartial)};
      // The end node joins the heap; every other node keeps its position and velocity (samples of
      // the string, so the crossing adds no error to the state); the new end carries the string to
      // the front through the node before (its mass follows at the next refresh).
      (end.after ? arc.last : arc.first) = inner;
    } else {
      if (!end.insertable) return {EventAction::Kind::kStop, "the heap has run empty"};
      // A new node comes out at the material point s_k ± h of the string near the front (its
      // interpolant through the end nodes and the front), with the velocity there.
      const HeapGeometry<dim> geo = heap_geometry<dim>(x, v, front, node, end.after, arc.num_links(), h_);
      const double at = end.after ? h_ : -h_;
      x.col(outer) = geo.curve.position(at);
      v.col(outer) = geo.curve.velocity(at);
      (end.after ? arc.last : arc.first) = outer;
    }
    model.rebuild();
    model.refresh();
    return {EventAction::Kind::kTransfer, {}};
  }
  ArcRange& A = model.arcs()[static_cast<std::size_t>(front.arc_minus)];
  ArcRange& B = model.arcs()[static_cast<std::size_t>(front.arc_plus)];
  // e0: the fold reached B's first node (it joins A); e1: it reached A's last node (it joins B).
  const bool to_A = e0 != 0;
  if (to_A && B.num_links() == 0) return {EventAction::Kind::kStop, "the fold has reached the end of the string"};
  if (!to_A && (A.num_links() == 0 || model.is_prescribed(A.last)))
    return {EventAction::Kind::kStop, "the fold has reached the start of the string"};
  // Mass parcels: each link's mass is split between its two nodes (½–½ for a full link, l_A–l_B
  // for the folded one). Moving the fold changes the split of two links; the mass that changes
  // node carries its velocity, so momentum is conserved exactly.
  const int a = A.last, b = B.first;
  const int lo = to_A ? a : a - 1;  // the two links whose split changes: (lo, lo+1), (lo+1, lo+2)
  auto shares = [&](int j) -> std::pair<double, double> {
    // split of link (j, j+1) between its start and end node under the current arcs
    if (model.arc_of(j) == model.arc_of(j + 1)) return {0.5 * lambda_ * h_, 0.5 * lambda_ * h_};
    return {lambda_ * fs_[f].l_minus, lambda_ * fs_[f].l_plus};
  };
  const auto old0 = shares(lo), old1 = shares(lo + 1);
  Eigen::Vector3d mass;
  Points<dim> mom(dim, 3);
  for (int q = 0; q < 3; ++q) {
    mass[q] = model.masses()[lo + q];
    mom.col(q) = model.masses()[lo + q] * v.col(lo + q);
  }
  if (to_A) {
    A.last = b;
    B.first = b + 1;
  } else {
    A.last = a - 1;
    B.first = a;
  }
  model.rebuild();
  model.refresh();
  const auto new0 = shares(lo), new1 = shares(lo + 1);
  const Points<dim> v_old = v;
  auto move = [&](int j, std::pair<double, double> before_split, std::pair<double, double> after_split) {
    const double delta = after_split.first - before_split.first;  // change of the start node's share
    const int q = j - lo;
    const int giver = delta < 0 ? j : j + 1;  // the node whose material moves, with its velocity
    mass[q] += delta;
    mom.col(q) += delta * v_old.col(giver);
    mass[q + 1] -= delta;
    mom.col(q + 1) -= delta * v_old.col(giver);
  };
  move(lo, old0, new0);
  move(lo + 1, old1, new1);
  for (int q = 0; q < 3; ++q)
    if (!model.is_prescribed(lo + q) && model.in_arc(lo + q)) v.col(lo + q) = mom.col(q) / mass[q];
  return {EventAction::Kind::kTransfer, {}};
}

template <int dim>
StringModel<dim> make_front_model(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                                  std::vector<PrescribedNode<dim>> prescribed, std::vector<HeapSpec<dim>> heaps,
                                  std::optional<FoldSpec> fold, const FrontOptions& fronts,
                                  const StringModelOptions& options) {
  return StringModel<dim>(std::move(chain), std::move(forces), std::move(prescribed), options,
                          std::make_unique<FrontTracker<dim>>(std::move(heaps), fold, fronts));
}

template class FrontTracker<2>;
template class FrontTracker<3>;
template StringModel<2> make_front_model<2>(Chain<2>, std::vector<std::unique_ptr<Force<2>>>,
                                            std::vector<PrescribedNode<2>>, std::vector<HeapSpec<2>>,
                                            std::optional<FoldSpec>, const FrontOptions&, const StringModelOptions&);
template StringModel<3> make_front_model<3>(Chain<3>, std::vector<std::unique_ptr<Force<3>>>,
                                            std::vector<PrescribedNode<3>>, std::vector<HeapSpec<3>>,
                                            std::optional<FoldSpec>, const FrontOptions&, const StringModelOptions&);

}  // namespace chainsim
