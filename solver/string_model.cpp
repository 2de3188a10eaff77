// The one discrete string as an ODE system: see string_model.hpp.
#include "string_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "quadratic_string.hpp"
#include "slack_module.hpp"

namespace chainsim {

namespace {
/// A link shorter than this fraction of its material length is a trial state the model cannot use
/// (the unit vector e_j is undefined): ARKODE retries with a smaller step.
constexpr double kCollapsedLink = 1e-6;
/// A bent link's part on either side of its point may be this short (a node crossing an edge passes
/// within 1e-8 h of it, shocks/edge_front.hpp).
constexpr double kBentLinkFloor = 1e-10;
/// A signed side of a link bent over a point is measured along its side's line within this share of the
/// link of the point (point_bend_sides).
constexpr double kNearPoint = 1e-4;
/// A bent link's node has passed its point (point_bend_sides: its partial length negative) where the
/// node lies past the point within this cosine of the side's direction (60°).
constexpr double kPassedCone = 0.5;
/// A link bent over a circle: the share of its length below which a free end's straight part is
/// floored in the quadratic term (n·v)²/s (the end has just left the circle, or is about to land).
constexpr double kCircleBendFloor = 1e-6;
/// The projection is converged when every link length is right to the larger of this relative
/// accuracy and the round-off of its coordinates, kRoundoffUlps · ε · max|x| / h_min: a link's length
/// cannot be represented more accurately than its end points' coordinates.
constexpr double kProjectionTolerance = 1e-14;
constexpr double kRoundoffUlps = 64;
/// The largest share of the physical acceleration scale the drift control's response to round-off
/// may take (evaluate_current).
constexpr double kDriftRoundoff = 1e-6;
constexpr int kProjectionIterations = 60;
// Arcs in increasing order of their nodes, disjoint, within the string's n nodes, and a closed arc only as the
// whole of a closed string: what tension_forces_of_string's pass needs.
bool arcs_in_order(const std::vector<ArcRange>& arcs, int n, bool closed_string) {
  int previous_last = -1;
  for (const ArcRange& arc : arcs) {
    if (arc.first <= previous_last || arc.last < arc.first || arc.last >= n) return false;
    if (arc.closed && !(closed_string && arc.first == 0 && arc.last == n - 1)) return false;
    previous_last = arc.last;
  }
  return true;
}

/// slack = allow: whether a taut link goes slack at a state where it is `gap` (of h) short of its length (accept_step,
/// and the frames interpolated inside a step, projected_state): short by more than `slack_gap` (kSlackGap) and
/// released, by the last evaluation (no tension) or by any since the last accepted step (`released`).
bool goes_slack(double gap, double slack_gap, double tension, bool released) {
  return gap > slack_gap && (!(tension > 0) || released);
}
}  // namespace

const char* to_string(SlackPolicy policy) {
  switch (policy) {
    case SlackPolicy::kStop: return "stop";
    case SlackPolicy::kWarn: return "warn";
    case SlackPolicy::kAllow: return "allow";
    case SlackPolicy::kIgnore: break;
  }
  return "ignore";
}

std::string SlackReport::message() const {
  return fmt::format("slack at t = {:.9g} s: link {} (s = {:.6g} m from node 0) has tension T = {:.6g} N < 0 "
                     "(tension scale {:.6g} N, the larger of max |T| and the physical tension lambda (|g| l + max |v|^2 + l max "
                     "|a_driven|) + sum |loads|); an inextensible string "
                     "cannot push, so the model does not apply",
                     t, link, s_mid, tension, scale);
}

void StringModelOptions::validate() const {
  require_in_range("solver.stabilization_time", stabilization_time, 0.0, INFINITY);
  require_in_range("solver.slack_tolerance", slack_tolerance, 0.0, 1.0);
  require_in_range("solver.snap_restitution", snap_restitution, 0.0, 1.0);
  if (rotation && !(rotation->omega.allFinite() && rotation->center.allFinite()))
    throw InputError("velocity.omega and velocity.center of a rigid rotation must be finite numbers");
  if (backend != "auto") make_tension_backend(backend);  // throws InputError for an unknown name
  if (linear_solver != "auto" && linear_solver != "banded" && linear_solver != "klu")
    throw InputError(fmt::format("solver.linear_solver = \"{}\" is not allowed; valid values: \"auto\", \"banded\", \"klu\"",
                                 linear_solver));
  if (elements != "links" && elements != "quadratic")
    throw InputError(fmt::format("string.elements = \"{}\" is not allowed; valid values: \"links\", \"quadratic\"",
                                 elements));
}

template <int dim>
StringModel<dim>::StringModel(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                              std::vector<PrescribedNode<dim>> prescribed, const StringModelOptions& options,
                              std::unique_ptr<StringModule<dim>> module)
    : chain_(std::move(chain)),
      forces_(std::move(forces)),
      prescribed_(std::move(prescribed)),
      options_(options),
      module_(std::move(module)) {
  options_.validate();
  const int n = chain_.num_nodes(), L = chain_.num_links();
  if (allows_slack()) {
    // Unilateral links: a module of their own (the snap root function, W_snap, the momentum ledger),
    // wrapped around the fronts' module if there is one.
    if (options_.elements == "quadratic")
      throw InputError("solver.slack = \"allow\" needs link elements: string.elements = \"quadratic\" has no "
                       "tension per link to release");
    module_ = make_slack_module<dim>(std::move(module_));
    slack_.assign(static_cast<std::size_t>(L), 0);
    slack_offset_.assign(static_cast<std::size_t>(L), 0.0);
    release_flight_.assign(static_cast<std::size_t>(L), 0);
    rebound_time_.assign(static_cast<std::size_t>(L), NAN);
    rebound_speed_.assign(static_cast<std::size_t>(L), NAN);
    released_.assign(static_cast<std::size_t>(L), 0);
  }
  // 1. The arcs: the whole string, or the module's layout.
  if (module_) {
    arcs_ = module_->initial_arcs(chain_);
    num_ledgers_ = module_->num_ledgers();
  } else {
    arcs_ = {ArcRange{0, n - 1, chain_.closed()}};
  }
  arc_of_.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t k = 0; k < arcs_.size(); ++k)
    for (int i = arcs_[k].first; i <= arcs_[k].last; ++i) arc_of_[static_cast<std::size_t>(i)] = static_cast<int>(k);
  // 2. Which nodes are prescribed; what may be prescribed or loaded.
  path_of_.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t k = 0; k < prescribed_.size(); ++k) {
    const int node = prescribed_[k].node;
    if (node < 0 || node >= n)
      throw InputError(fmt::format("prescribed node {} does not exist: the string has nodes 0..{}", node, n - 1));
    if (path_of_[node] >= 0) throw InputError(fmt::format("node {} has two prescribed motions", node));
    CHAINSIM_VERIFY(prescribed_[k].path != nullptr, "a prescribed node needs a path");
    if (!in_arc(node)) throw InputError(fmt::format("prescribed node {} lies in no arc (the module holds it)", node));
    path_of_[node] = static_cast<int>(k);
  }
  for (const auto& force : forces_) {
    CHAINSIM_VERIFY(force != nullptr, "null force");
    if (const auto* load = dynamic_cast<const EndLoad<dim>*>(force.get())) {
      if (load->node() < 0 || load->node() >= n)
        throw InputError(fmt::format("the end load acts on node {}, which does not exist", load->node()));
      if (path_of_[load->node()] >= 0)
        throw InputError(fmt::format("node {} is both loaded and prescribed: a driven or fixed end takes no load",
                                     load->node()));
      if (!in_arc(load->node())) throw InputError(fmt::format("the end load acts on node {}, in no arc (the module holds it)", load->node()));
    }
  }
  for (int j = 0; j < L; ++j)
    if (in_arc(chain_.link_start(j)) && in_arc(chain_.link_end(j)) && path_of_[chain_.link_start(j)] >= 0 &&
        path_of_[chain_.link_end(j)] >= 0)
      throw InputError(fmt::format("link {} joins two prescribed nodes ({} and {}): its tension is undetermined; "
                                   "use more nodes",
                                   j, chain_.link_start(j), chain_.link_end(j)));
  if (options_.stabilization_time > 0) alpha_ = beta_ = 1.0 / options_.stabilization_time;
  if (options_.elements == "quadratic") {
    if (module_)
      throw InputError("string.elements = \"quadratic\" does not meet fronts (heaps, folds): use elements = \"links\" "
                       "for a scene with fronts");
    quadratic_ = std::make_shared<QuadraticString<dim>>(chain_, prescribed_);
  }
  // 3. Workspace, the state, then slots, masses and the tension system.
  for (Points<dim>* p : {&a_, &force_, &tension_force_, &b_}) *p = Points<dim>::Zero(dim, n);
  // Per node only where they exist: the module's forces with a module, the reactions at the
  // prescribed nodes (column k for prescribed_[k]): 32 bytes per 2D node less for a plain string;
  // the non-conservative forces with such a force (or quadratic elements, which take the array),
  // 16 bytes more (force_nc(i) stands in with +0.0, the very terms the zeroed array added).
  module_force_ = Points<dim>::Zero(dim, module_ ? n : 0);
  const bool nonconservative =
      quadratic_ || std::any_of(forces_.begin(), forces_.end(), [](const auto& f) { return !f->conservative(); });
  force_nc_ = Points<dim>::Zero(dim, nonconservative ? n : 0);
  reaction_ = Points<dim>::Zero(dim, static_cast<Eigen::Index>(prescribed_.size()));
  for (Points<dim>* p : {&dx_, &dv_, &e_}) *p = Points<dim>::Zero(dim, L);
  l_ = Eigen::VectorXd::Zero(L);
  x_ = chain_.positions();
  v_ = chain_.velocities();
  for (const auto& p : prescribed_) x_.col(p.node) = p.path->position(0.0);
  rebuild();
  if (num_free_ == 0) throw InputError("every node of the string is prescribed: nothing to solve");
  if (module_) module_->initialize(*this);
  if (options_.sliding_speed) set_sliding_velocities(*options_.sliding_speed);
}

template <int dim>
void StringModel<dim>::rebuild() {
  const int n = chain_.num_nodes(), L = chain_.num_links();
  arc_of_.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t k = 0; k < arcs_.size(); ++k)
    for (int i = arcs_[k].first; i <= arcs_[k].last; ++i) arc_of_[static_cast<std::size_t>(i)] = static_cast<int>(k);
  slot_.assign(static_cast<std::size_t>(n), -1);
  num_free_ = 0;
  for (int i = 0; i < n; ++i)
    if (in_arc(i) && path_of_[i] < 0) slot_[i] = num_free_++;
  find_free_runs();
  // Each arc with a link owns a block of unknowns; its links' masses are lumped on their nodes.
  base_mass_ = Eigen::VectorXd::Zero(n);
  link_unknown_.assign(static_cast<std::size_t>(L), -1);
  first_unknown_.assign(arcs_.size(), -1);
  std::vector<int> arc_links;
  std::vector<bool> arc_closed;
  int unknown = 0;
  h_min_ = INFINITY;
  const double lambda = chain_.density();
  for (std::size_t k = 0; k < arcs_.size(); ++k) {
    const ArcRange& arc = arcs_[k];
    if (arc.num_links() == 0) continue;
    first_unknown_[k] = unknown;
    for (int q = 0; q < arc.num_links(); ++q) {
      const int j = arc.first + q;
      link_unknown_[static_cast<std::size_t>(j)] = unknown + q;
      base_mass_[chain_.link_start(j)] += 0.5 * lambda * chain_.link_length(j);
      base_mass_[chain_.link_end(j)] += 0.5 * lambda * chain_.link_length(j);
    }
    for (int q = 0; q < arc.num_links(); ++q) h_min_ = std::min(h_min_, chain_.link_length(arc.first + q));
    unknown += arc.num_links();
    arc_links.push_back(arc.num_links());
    arc_closed.push_back(arc.closed);
  }
  if (quadratic_) base_mass_ = quadratic_->mass_rows();  // the consistent load M g, momentum 1ᵀ M v
  if (system_) solves_ += system_->num_solves();
  system_ = arc_links.empty() ? nullptr : std::make_unique<TensionSystem>(arc_links, arc_closed, options_.backend);
  if (system_) system_->set_two_ended(contacts_.empty() && bends_.empty());  // (until the next refresh())
  m_ = base_mass_;
  w_ = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i)
    if (slot_[i] >= 0) w_[i] = 1.0 / m_[i];
  // refresh()'s copy, with a module only (8 bytes a node: tests/unit/test_memory.cpp).
  if (module_)
    base_w_ = w_;
  else
    base_w_.resize(0);
  // refresh()'s floor of a free node's mass: 1e-12 of a link's (the first link's material length: a module
  // with fronts has links of equal length).
  lost_mass_floor_ = L > 0 ? 1e-12 * lambda * chain_.link_length(0) : 0.0;
  // A slack link that left the arcs (taken into a heap, or the folded link at a fold) is no longer a
  // link of the tension system: the front's jump conditions hold its material.
  for (int j = 0; j < L; ++j)
    if (link_slack(j) && link_unknown_[static_cast<std::size_t>(j)] < 0) set_slack(j, false);
}

template <int dim>
Vec<dim> StringModel<dim>::uniform_field() const {
  Vec<dim> a = Vec<dim>::Zero();
  for (const auto& force : forces_)
    if (const std::optional<Vec<dim>> field = force->uniform_field()) a += *field;
  return a;
}

template <int dim>
void StringModel<dim>::unpack_state(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  fill_moving(t, y, x_, v_);
}

template <int dim>
void StringModel<dim>::unpack(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Points<dim>& x,
                              Points<dim>& v) const {
  x = x_;  // nodes in no arc keep their last known state
  v = v_;
  fill_moving(t, y, x, v);
}

template <int dim>
void StringModel<dim>::fill_moving(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Points<dim>& x,
                                   Points<dim>& v) const {
  const int voff = dim * num_free_;
  for (const FreeRun& run : free_runs_) {
    Eigen::Map<Eigen::VectorXd>(x.col(run.node).data(), dim * run.count) = y.segment(dim * run.slot, dim * run.count);
    Eigen::Map<Eigen::VectorXd>(v.col(run.node).data(), dim * run.count) =
        y.segment(voff + dim * run.slot, dim * run.count);
  }
  for (const int i : prescribed_in_arcs_) {
    const EndPath<dim>& path = *prescribed_[static_cast<std::size_t>(path_of_[i])].path;
    x.col(i) = path.position(t);
    v.col(i) = path.velocity(t);
  }
}

template <int dim>
void StringModel<dim>::find_free_runs() {
  free_runs_.clear();
  prescribed_in_arcs_.clear();
  for (int i = 0; i < chain_.num_nodes(); ++i) {
    const int k = slot_[i];
    if (k >= 0 && !free_runs_.empty() && free_runs_.back().node + free_runs_.back().count == i &&
        free_runs_.back().slot + free_runs_.back().count == k)
      ++free_runs_.back().count;
    else if (k >= 0)
      free_runs_.push_back({i, k, 1});
    else if (arc_of_[i] >= 0)
      prescribed_in_arcs_.push_back(i);
  }
}

template <int dim>
void StringModel<dim>::links() {
  // The links of the arcs in for_each_link's order, written as plain loops over raw pointers held in
  // locals: Eigen's vector stores may alias anything, so a lambda's captures and the members would be
  // reloaded after each of them (17.6 k instructions a call at 250 links; the same numbers).
  using CMap = Eigen::Map<const Vec<dim>>;
  using Map = Eigen::Map<Vec<dim>>;
  const double* const x = x_.data();
  const double* const v = v_.data();
  double* const dx = dx_.data();
  double* const dv = dv_.data();
  double* const e = e_.data();
  double* const l_of = l_.data();
  const double* const h = chain_.link_lengths().data();
  const int num_nodes = chain_.num_nodes();
  double x_max = 0;
  for (const ArcRange& arc : arcs_) {
    const int nl = arc.num_links();
    for (int q = 0; q < nl; ++q) {
      const int j = arc.first + q, a = j, b = j + 1 == num_nodes ? 0 : j + 1;  // chain_.link_start, link_end
      Map dxj(dx + dim * j);
      dxj = CMap(x + dim * b) - CMap(x + dim * a);
      Map(dv + dim * j) = CMap(v + dim * b) - CMap(v + dim * a);
      const double l = dxj.norm();
      l_of[j] = l;
      if (!(l > kCollapsedLink * h[j]) || !std::isfinite(l)) {
        // A slack link may be as short as anything, its ends may pass each other (it carries no tension,
        // its row is out of the system): no direction. A taut one that collapses is a degenerate state;
        // not a link bent over a point, whose length and directions are its sides' (bend_links, below;
        // point_bend_sides refuses sides that collapse): over a peg (sides antiparallel) its chord passes
        // through zero where the peg is at its midpoint. A link over a cylinder keeps the chord's test (its
        // arc length may go negative in a trial state at loose tolerances, which the drift control takes back).
        if (!(std::isfinite(l) && (link_slack(j) || point_bent(j))))
          throw RecoverableError(fmt::format("link {} has collapsed to length {:g}", j, l));
        Map(e + dim * j).setZero();
      } else {
        Map(e + dim * j) = dxj / l;
      }
      // every node of the arcs once: each link's start, and the end of an open arc's last link
      x_max = std::max(x_max, CMap(x + dim * a).cwiseAbs().maxCoeff());
      if (q + 1 == nl && !arc.closed) x_max = std::max(x_max, CMap(x + dim * b).cwiseAbs().maxCoeff());
    }
  }
  x_max_ = x_max;
  if (!bends_.empty()) bend_links();
}

template <int dim>
void StringModel<dim>::bend_link(int link, const Vec<dim>& point, bool signed_minus, bool signed_plus) {
  if (quadratic_) throw InputError("a link bent over a point (an edge) needs link elements ([string] elements = \"links\")");
  if (link < 0 || link >= chain_.num_links()) throw InputError(fmt::format("bend_link: no link {}", link));
  // The directions to and from the point now: a side at an end of its arc is signed along them
  // (side_reference), where no link beyond its node gives the direction the string runs.
  const Vec<dim> to_a = point - x_.col(chain_.link_start(link)), from_b = x_.col(chain_.link_end(link)) - point;
  if (!(to_a.norm() > 0) || !(from_b.norm() > 0))
    throw RecoverableError(fmt::format("link {} is bent over a point on one of its nodes", link));
  Bend* bend = nullptr;
  for (Bend& b : bends_)
    if (b.link == link) bend = &b;
  if (!bend) {
    bends_.emplace_back();
    bend = &bends_.back();
    bend->link = link;
  }
  bend->point = point;
  bend->bent_minus = to_a / to_a.norm();
  bend->bent_plus = from_b / from_b.norm();
  bend->signed_minus = signed_minus;
  bend->signed_plus = signed_plus;
}

template <int dim>
void StringModel<dim>::bend_link_on_circle(int link, const Vec<dim>& center, double radius, double sigma, bool a_on,
                                           bool b_on) {
  if (quadratic_) throw InputError("a link bent over a circle needs link elements ([string] elements = \"links\")");
  if (dim != 2) throw InputError("a link bent over a circle is two-dimensional");
  if (link < 0 || link >= chain_.num_links()) throw InputError(fmt::format("bend_link_on_circle: no link {}", link));
  Bend bend;
  bend.link = link;
  bend.circle = true;
  bend.center = center;
  bend.radius = radius;
  bend.sigma = sigma;
  bend.a_on = a_on;
  bend.b_on = b_on;
  for (Bend& b : bends_)
    if (b.link == link) {
      b = bend;
      return;
    }
  bends_.push_back(bend);
}

template <int dim>
void StringModel<dim>::clear_circle_bends() {
  bends_.erase(std::remove_if(bends_.begin(), bends_.end(), [](const Bend& b) { return b.circle; }), bends_.end());
}

template <int dim>
double StringModel<dim>::bend_arc(int link) const {
  const Bend* bend = bends_.empty() ? nullptr : bend_of(link);
  return bend && bend->circle ? bend->arc : std::numeric_limits<double>::quiet_NaN();
}

template <int dim>
double StringModel<dim>::bend_straight(int link, bool at_end) const {
  const Bend* bend = bends_.empty() ? nullptr : bend_of(link);
  if (!bend || !bend->circle) return std::numeric_limits<double>::quiet_NaN();
  return at_end ? bend->l_plus : bend->l_minus;
}

template <int dim>
template <class Position>
typename StringModel<dim>::CircleBend StringModel<dim>::circle_bend(const Bend& bend, const Position& x) const {
  CircleBend out;
  if constexpr (dim == 2) {
    const int j = bend.link, a = chain_.link_start(j), b = chain_.link_end(j);
    const double R = bend.radius, sg = bend.sigma;
    // One end: its angle on the circle (a free end: the tangent point of the line through it), its
    // straight part s and its share of the quadratic term. `out_end`: the end node b (the string goes
    // from the circle to it); the start node a enters the circle.
    struct End {
      double theta, s, q;
    };
    auto end = [&](int i, bool on, bool out_end) -> End {
      const Vec<2> r = Vec<2>(x(i)) - bend.center, v = v_.col(i);
      const double d = r.norm(), phi = std::atan2(r[1], r[0]);
      if (on) {  // R σ θ: its second derivative at zero acceleration, −2 σ R (n·v)(t·v)/d²
        const Vec<2> n = r / d, t(-n[1], n[0]);
        const double q = -2 * sg * R * n.dot(v) * t.dot(v) / (d * d);
        return {phi, 0.0, out_end ? q : -q};
      }
      // Off the circle: s = √(d² − R²) along the tangent at θ = φ ∓ σ atan(s/R); d²s/dt² − R σ θ̈ at zero
      // acceleration is (n(θ)·v)²/s (the point-bend's |v⊥|²/l), its s floored where it vanishes.
      const double s = d > R ? std::sqrt((d - R) * (d + R)) : 0.0;
      const double theta = phi + (out_end ? -sg : sg) * std::atan2(s, R);
      const double vn = Vec<2>(std::cos(theta), std::sin(theta)).dot(v);
      return {theta, s, vn * vn / std::max(s, kCircleBendFloor * chain_.link_length(j))};
    };
    const End ea = end(a, bend.a_on, false), eb = end(b, bend.b_on, true);
    double dtheta = eb.theta - ea.theta;
    dtheta -= 2 * kPi * std::round(dtheta / (2 * kPi));  // into [−π, π]
    out.arc = R * sg * dtheta;
    out.s_a = ea.s;
    out.s_b = eb.s;
    out.l = ea.s + out.arc + eb.s;
    out.q = ea.q + eb.q;
    out.e_minus = sg * Vec<2>(-std::sin(ea.theta), std::cos(ea.theta));
    out.e_plus = sg * Vec<2>(-std::sin(eb.theta), std::cos(eb.theta));
  }
  return out;
}

template <int dim>
Vec<dim> StringModel<dim>::end_direction_at_contact(int j) const {
  if (!bends_.empty())
    if (const Bend* bend = bend_of(j)) return bend->e_plus;
  return e_.col(j);
}

template <int dim>
void StringModel<dim>::bend_links() {
  for (Bend& bend : bends_) {
    if (bend.circle) {
      const CircleBend c = circle_bend(bend);
      l_[bend.link] = c.l;
      e_.col(bend.link) = c.e_minus;
      bend.e_plus = c.e_plus;
      bend.l_minus = c.s_a;
      bend.l_plus = c.s_b;
      bend.arc = c.arc;
      bend.q = c.q;
      continue;
    }
    const PointBendSides sides = point_bend_sides(bend, [this](int i) { return x_.col(i); }, true);
    const int j = bend.link;
    bend.l_minus = sides.l_minus;
    bend.l_plus = sides.l_plus;
    bend.near_minus = sides.near_minus;
    bend.near_plus = sides.near_plus;
    l_[j] = bend.l_minus + bend.l_plus;
    e_.col(j) = sides.e_minus;
    bend.e_plus = sides.e_plus;
    bend.e_minus_last = e_.col(j);
    bend.e_plus_last = bend.e_plus;
  }
}

template <int dim>
template <class Position>
Vec<dim> StringModel<dim>::side_reference(const Bend& bend, bool at_end, const Position& x) const {
  // Along the link beyond the node (from or to the point it is bent over, if it is bent over one), as
  // the string runs there; at an end of the arc, the bent link's own direction when it was bent.
  const int j = bend.link, a = chain_.link_start(j), b = chain_.link_end(j);
  const int arc = arc_of_[static_cast<std::size_t>(at_end ? b : a)];
  if (arc >= 0) {
    const ArcRange& range = arcs_[static_cast<std::size_t>(arc)];
    if (!at_end && a > range.first) {
      const Bend* other = bend_of(a - 1);
      return other && !other->circle ? Vec<dim>((x(a) - other->point).normalized())
                                     : Vec<dim>((x(a) - x(a - 1)).normalized());
    }
    if (at_end && b < range.last) {
      const Bend* other = bend_of(b);
      return other && !other->circle ? Vec<dim>((other->point - x(b)).normalized())
                                     : Vec<dim>((x(b + 1) - x(b)).normalized());
    }
  }
  return at_end ? bend.bent_plus : bend.bent_minus;
}

template <int dim>
template <class Position>
typename StringModel<dim>::PointBendSides StringModel<dim>::point_bend_sides(const Bend& bend, const Position& x,
                                                                             bool directions) const {
  const int j = bend.link, a = chain_.link_start(j), b = chain_.link_end(j);
  const Vec<dim> to_a = bend.point - x(a), from_b = x(b) - bend.point;
  const double floor = kBentLinkFloor * chain_.link_length(j);
  PointBendSides out;
  // One side: d from its node to the point (−) or from the point to its node (+); σ = −1 where the
  // node has passed the point along the side's direction beyond it, within kPassedCone of that line (a
  // node on a straight line through the point: l = σ |d| runs on through zero, e = d / l stays; a node
  // that passes beside the point, further from it than from that line, keeps σ = 1 and its l = |d|
  // continuous, as before). An unsigned side (bend_link) keeps σ = 1.
  auto side = [&](const Vec<dim>& d, bool at_end, const Vec<dim>& last, double& l, Vec<dim>& e, bool& near) {
    const double r = d.norm();
    const bool signed_side = at_end ? bend.signed_plus : bend.signed_minus;
    near = signed_side && r < kNearPoint * chain_.link_length(j);
    if (near) {
      // Near the point the side's own line measures it: its node's error across that line (the
      // integrator's, or round-off) would turn d / |d| by error / |d|, and the row's |v⊥|²/l with it
      // (the row drops that term for such a side: l = ref·d has no 1/l in its second derivative).
      const Vec<dim> ref = side_reference(bend, at_end, x);
      l = ref.dot(d);
      if (directions) e = ref;
      if (directions && !(std::abs(l) > 0)) e = last.squaredNorm() > 0 ? last : ref;
      return;
    }
    l = signed_side && side_reference(bend, at_end, x).dot(d) < -kPassedCone * r ? -r : r;
    if (!directions) return;
    // A node within the floor of the point (a root function's search may pass there) keeps the
    // direction of its side from the last evaluation.
    if (!(r > floor) && last.squaredNorm() > 0) {
      e = last;
      return;
    }
    if (!(r > 0) || !std::isfinite(r))
      throw RecoverableError(fmt::format("link {} has reached the point it is bent over ({:g} and {:g} m from it)", j,
                                         to_a.norm(), from_b.norm()));
    e = d / l;
  };
  side(to_a, false, bend.e_minus_last, out.l_minus, out.e_minus, out.near_minus);
  side(from_b, true, bend.e_plus_last, out.l_plus, out.e_plus, out.near_plus);
  if (directions && !(out.l_minus + out.l_plus > 0 && std::isfinite(out.l_minus + out.l_plus)))
    throw RecoverableError(fmt::format("link {} has passed the point it is bent over (its parts {:g} and {:g} m)", j,
                                       out.l_minus, out.l_plus));
  return out;
}

template <int dim>
typename StringModel<dim>::PointBendSides StringModel<dim>::bent_sides(int link) const {
  const Bend* bend = bends_.empty() ? nullptr : bend_of(link);
  CHAINSIM_VERIFY(bend && !bend->circle, "bent_sides: the link is not bent over a point");
  return point_bend_sides(*bend, [this](int i) { return x_.col(i); }, true);
}

template <int dim>
Vec<dim> StringModel<dim>::bend_side_direction(int link, bool at_end) const {
  const Bend* bend = bends_.empty() ? nullptr : bend_of(link);
  CHAINSIM_VERIFY(bend && !bend->circle, "bend_side_direction: the link is not bent over a point");
  return side_reference(*bend, at_end, [this](int i) { return x_.col(i); });
}

template <int dim>
double StringModel<dim>::bend_rate(const Bend& bend) const {
  const int a = chain_.link_start(bend.link), b = chain_.link_end(bend.link);
  return bend.e_plus.dot(v_.col(b)) - e_.col(bend.link).dot(v_.col(a));
}

template <int dim>
const typename StringModel<dim>::Bend* StringModel<dim>::bend_of(int link) const {
  for (const Bend& bend : bends_)
    if (bend.link == link) return &bend;
  return nullptr;
}

template <int dim>
double StringModel<dim>::current_length(int j) const {
  const Vec<dim>& a = x_.col(chain_.link_start(j));
  const Vec<dim>& b = x_.col(chain_.link_end(j));
  if (const Bend* bend = bends_.empty() ? nullptr : bend_of(j)) {  // its length runs over its point
    if (bend->circle) return circle_bend(*bend).l;
    const PointBendSides sides = point_bend_sides(*bend, [this](int i) { return x_.col(i); }, false);
    return sides.l_minus + sides.l_plus;
  }
  return (b - a).norm();
}

template <int dim>
double StringModel<dim>::link_rate(int j) const {
  if (const Bend* bend = bends_.empty() ? nullptr : bend_of(j)) return bend_rate(*bend);
  return e_.col(j).dot(dv_.col(j));
}

template <int dim>
void StringModel<dim>::bend_couplings() {
  // The coupling of a bent link with the next link goes through its end node b, along e⁺.
  for_each_link([&](int j, int u, int next) {
    if (next < 0) return;
    for (const Bend& bend : bends_)
      if (bend.link == j) system_->set_coupling(u, w_[chain_.link_end(j)] * bend.e_plus.dot(e_.col(next)));
  });
}

template <int dim>
double StringModel<dim>::link_tension(int link) const {
  const int u = link_unknown_[static_cast<std::size_t>(link)];
  return u >= 0 && system_ ? system_->solution()[u] : std::numeric_limits<double>::quiet_NaN();
}

template <int dim>
Vec<dim> StringModel<dim>::bend_reaction() const {
  Vec<dim> r = Vec<dim>::Zero();
  for (const Bend& bend : bends_) {
    const int u = link_unknown_[static_cast<std::size_t>(bend.link)];
    if (u >= 0) r += system_->solution()[u] * (e_.col(bend.link) - bend.e_plus);
  }
  return r;
}

template <int dim>
double StringModel<dim>::capped_beta2() const {
  // The position term β² C of the drift control turns the round-off of the link lengths (the
  // constraint tolerance δ) into accelerations β² δ h. It may not exceed kDriftRoundoff of the
  // physical acceleration scale (physical_scales().tension / λℓ: weight, loads, drivers, speeds),
  // so β² is capped there: a string with none of them (at rest without weight or load) gets no
  // position term and no artificial tension, however short τ_b (β² = 1/τ_b² turned its round-off
  // into T = −1.5e165 N with τ_b = 1e-91 s). Ordinary runs are far below the cap (falling chain:
  // β² δ h = 1.7e-10 m/s² against 1e-5 m/s²) and keep β² = 1/τ_b².
  // physical_scales() is a pass over the nodes (10 k instructions at 250 links, at every right-hand
  // side). Its tension is the weight λ|g|ℓ plus terms ≥ 0, and rounding is monotone, so the cap
  // computed from the weight alone is a lower bound of the cap: when β² is below it, the cap does
  // not bind and β² is the same number without the pass.
  const double lambda_ell = chain_.density() * chain_.length();
  const double h_ref = std::isfinite(h_min_) ? h_min_ : chain_.length();
  const double beta2 = beta_ * beta_, denominator = constraint_tolerance() * h_ref;
  const double weight = chain_.density() * uniform_field().norm() * chain_.length();  // as physical_scales()
  if (beta2 <= kDriftRoundoff * (weight / lambda_ell) / denominator) return beta2;
  const double a_physical = physical_scales().tension / lambda_ell;
  return std::min(beta2, kDriftRoundoff * a_physical / denominator);
}

template <int dim>
long StringModel<dim>::tension_solves() const {
  return solves_ + (system_ ? system_->num_solves() : 0) + (quadratic_ ? quadratic_->solves() : 0);
}

template <int dim>
double StringModel<dim>::constraint_tolerance() const {
  return std::max(kProjectionTolerance, kRoundoffUlps * std::numeric_limits<double>::epsilon() * x_max_ / h_min_);
}

template <int dim>
void StringModel<dim>::assemble_matrix() {
  // Row j: T_{j−1} w_a (e_{j−1}·e_j) − T_j (w_a + w_b) + T_{j+1} w_b (e_j·e_{j+1}); the coupling of
  // link j with the next link of its arc goes through their shared node b = link_end(j).
  for_each_link([&](int j, int u, int next) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    system_->set_diagonal(u, -(w_[a] + w_[b]));  // its first write (zero() is optional: evaluate_current)
    if (next >= 0) system_->set_coupling(u, w_[b] * e_.col(j).dot(e_.col(next)));
  });
  if (!bends_.empty()) bend_couplings();
  if (!contacts_.empty()) contact_couplings();
  if (contact_stuck_) lock_stuck_links();
}

template <int dim>
std::pair<int, int> StringModel<dim>::node_links(int i) const {
  const int L = chain_.num_links();
  return {i > 0 ? i - 1 : (chain_.closed() ? L - 1 : -1), i < L ? i : -1};
}

template <int dim>
void StringModel<dim>::contact_friction_forces() {
  // Sliding: −μ N t̂, and the links' share of it in the acceleration, μ w (n·f) t̂ (the applied forces'
  // share is in b_i). Sticking: the tangential part of the force that holds the node, −(m b_i + f_i).
  contact_friction_.setZero(dim, static_cast<Eigen::Index>(contacts_.size()));
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const NodeContact<dim>& c = contacts_[k];
    if (!(c.mu > 0)) continue;
    const int i = c.node;
    Vec<dim> f;
    if (c.stuck) {
      const Vec<dim> hold = -(m_[i] * Vec<dim>(contact_b_.col(static_cast<Eigen::Index>(k))) + tension_force_.col(i));
      f = hold - c.normal.dot(hold) * c.normal;
    } else {
      f = -c.mu * contact_force_[k] * c.slide;
      a_.col(i) += w_[i] * c.mu * c.normal.dot(tension_force_.col(i)) * c.slide;
    }
    contact_friction_.col(static_cast<Eigen::Index>(k)) = f;
    external_ += f;
  }
}

template <int dim>
void StringModel<dim>::friction_couplings() {
  // A sliding node responds with w (P + μ t̂ nᵀ): to contact_couplings' w P add μ w t̂ nᵀ, whose entries
  // in its links' rows are −μ w (e·t̂)(n·e) on the diagonals and μ w (e·t̂)(n·e') across, not symmetric.
  for (const NodeContact<dim>& c : contacts_) {
    if (!(c.mu > 0) || c.stuck) continue;
    const int i = c.node;
    const auto [jm, jp] = node_links(i);
    const int um = jm >= 0 ? link_unknown_[static_cast<std::size_t>(jm)] : -1;
    const int up = jp >= 0 ? link_unknown_[static_cast<std::size_t>(jp)] : -1;
    const double wmu = w_[i] * c.mu;
    const Vec<dim> em = um >= 0 ? end_direction_at_contact(jm) : Vec<dim>::Zero();  // e⁺ for a bent link
    if (um >= 0) system_->add_diagonal(um, -wmu * em.dot(c.slide) * c.normal.dot(em));
    if (up >= 0) system_->add_diagonal(up, -wmu * e_.col(jp).dot(c.slide) * c.normal.dot(e_.col(jp)));
    if (um >= 0 && up >= 0)
      system_->add_couplings(um, wmu * em.dot(c.slide) * c.normal.dot(e_.col(jp)),
                             wmu * e_.col(jp).dot(c.slide) * c.normal.dot(em));
  }
}

template <int dim>
void StringModel<dim>::update_locked_links() {
  if (!contact_stuck_) {
    locked_.clear();
    return;
  }
  const std::size_t L = static_cast<std::size_t>(chain_.num_links());
  locked_.resize(L, 0);
  locked_tension_.resize(L, 0.0);
  last_tension_.resize(L, 0.0);
  for (std::size_t j = 0; j < L; ++j) {
    const bool now = w_[chain_.link_start(static_cast<int>(j))] == 0 && w_[chain_.link_end(static_cast<int>(j))] == 0;
    if (now && !locked_[j]) locked_tension_[j] = last_tension_[j];
    locked_[j] = now ? 1 : 0;
  }
}

template <int dim>
void StringModel<dim>::lock_stuck_links() {
  for_each_link([&](int j, int u, int) {
    if (!locked_[static_cast<std::size_t>(j)]) return;
    system_->add_diagonal(u, -(1.0 / m_[chain_.link_start(j)] + 1.0 / m_[chain_.link_end(j)]));
  });
}

template <int dim>
void StringModel<dim>::locked_rhs() {
  for_each_link([&](int j, int u, int) {
    if (!locked_[static_cast<std::size_t>(j)]) return;
    const double s = 1.0 / m_[chain_.link_start(j)] + 1.0 / m_[chain_.link_end(j)];
    system_->rhs(u) = -s * locked_tension_[static_cast<std::size_t>(j)];
  });
}

template <int dim>
void StringModel<dim>::contact_couplings() {
  // Node i held with normal n: its response to a force f is w_i P f, P = I − n nᵀ. In the rows of its
  // links jm (ending at i) and jp (starting at i) the entries w_i e·e' become w_i (e·e' − (e·n)(e'·n)).
  for (const NodeContact<dim>& c : contacts_) {
    const int i = c.node;
    const auto [jm, jp] = node_links(i);
    const int um = jm >= 0 ? link_unknown_[static_cast<std::size_t>(jm)] : -1;
    const int up = jp >= 0 ? link_unknown_[static_cast<std::size_t>(jp)] : -1;
    const Vec<dim> em = um >= 0 ? end_direction_at_contact(jm) : Vec<dim>::Zero();
    if (um >= 0) system_->add_diagonal(um, w_[i] * std::pow(em.dot(c.normal), 2));
    if (up >= 0) system_->add_diagonal(up, w_[i] * std::pow(e_.col(jp).dot(c.normal), 2));
    if (um >= 0 && up >= 0)
      system_->set_coupling(um, w_[i] * (em.dot(e_.col(jp)) - em.dot(c.normal) * e_.col(jp).dot(c.normal)));
  }
}

template <int dim>
void StringModel<dim>::constrain_contact_nodes() {
  contact_bn_.resize(contacts_.size());
  if (contact_friction_on_) contact_b_.resize(dim, static_cast<Eigen::Index>(contacts_.size()));
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const NodeContact<dim>& c = contacts_[k];
    const int i = c.node;
    if (c.stuck) {
      // Held completely: a_i = 0; its applied acceleration (w_i is 0 here) for the force that holds it.
      const Vec<dim> bi = (force_.col(i) + force_nc(i) + module_force_.col(i)) / m_[i];
      contact_bn_[k] = c.normal.dot(bi);
      contact_b_.col(static_cast<Eigen::Index>(k)) = bi;
      b_.col(i).setZero();
      continue;
    }
    // g'' = n·a + curvature = −2α g' − β² g: the surface's normal acceleration with the drift control.
    const double target = -c.curvature - 2 * alpha_ * c.normal.dot(v_.col(i)) - beta2_ * c.gap;
    contact_bn_[k] = c.normal.dot(b_.col(i));
    if (contact_friction_on_) contact_b_.col(static_cast<Eigen::Index>(k)) = b_.col(i);
    b_.col(i) += (target - contact_bn_[k]) * c.normal;
    // Sliding: the applied forces' share of the friction, −μ w N t̂ (the links' share is in the matrix).
    if (c.mu > 0) b_.col(i) -= c.mu * (target - contact_bn_[k]) * c.slide;
  }
}

template <int dim>
double StringModel<dim>::place_contact_nodes() {
  double worst = 0;
  for (const NodeContact<dim>& c : contacts_) {
    x_.col(c.node) -= c.gap * c.normal;
    worst = std::max(worst, std::abs(c.gap) / h_min_);
  }
  return worst;
}

template <int dim>
double StringModel<dim>::friction_power() const {
  double p = 0;
  if (!contact_friction_on_) return p;
  for (std::size_t k = 0; k < contacts_.size(); ++k)
    p += contact_friction_.col(static_cast<Eigen::Index>(k)).dot(v_.col(contacts_[k].node));
  return p;
}

template <int dim>
double StringModel<dim>::contact_power() const {
  double p = 0;
  for (std::size_t k = 0; k < contacts_.size(); ++k)
    p += contact_force_[k] * contacts_[k].normal.dot(v_.col(contacts_[k].node));
  return p;
}

template <int dim>
void StringModel<dim>::refresh() {
  if (!module_) return;
  m_ = base_mass_;
  module_force_.setZero();
  module_->add_mass_and_forces(*this, m_, module_force_);
  // w_i = 1/m_i, the same number as rebuild()'s where the module left the mass as it was (all but the
  // few nodes of its partial links): a division per node at every right-hand side spared.
  const double *const m = m_.data(), *const base = base_mass_.data(), *const base_w = base_w_.data();
  double* const w = w_.data();
  // Over the free nodes' runs (the nodes with a slot), without a test of slot_ per node: a branch per node
  // less in the loop of every right-hand side. The same pass tells whether a free node is at or below the
  // floor of lost_mass_floor_ (a front overshot it: its partial link took more than the node's share), without
  // a branch; only then are the runs scanned again for the first such node. The module's own scan over its arcs
  // was a pass of its own at every right-hand side (3.6 % of the folded compare on 800 nodes).
  const double floor = lost_mass_floor_;
  bool any_light = false;
  for (const FreeRun& run : free_runs_)
    for (int i = run.node, end = run.node + run.count; i < end; ++i) {
      w[i] = base[i] > 0 && m[i] == base[i] ? base_w[i] : 1.0 / m[i];
      any_light |= !(m[i] > floor);
    }
  if (any_light)
    for (const FreeRun& run : free_runs_)
      for (int i = run.node, end = run.node + run.count; i < end; ++i)
        if (!(m[i] > floor)) throw RecoverableError(fmt::format("node {} has lost its mass (a front overshot it)", i));
  contacts_.clear();
  module_->node_contacts(*this, contacts_);
  constraints_.clear();
  module_->node_constraints(*this, constraints_);
  contact_friction_on_ = contact_stuck_ = false;
  for (const NodeContact<dim>& c : contacts_) {
    if (c.mu > 0) contact_friction_on_ = true;
    if (c.stuck) {
      contact_stuck_ = true;
      w_[c.node] = 0;  // held completely
    }
  }
  if (contact_stuck_ || !locked_.empty()) update_locked_links();
  if (system_) system_->set_two_ended(contacts_.empty() && bends_.empty());  // (TensionSystem::set_two_ended)
}

template <int dim>
void StringModel<dim>::tension_forces_of_string(const Eigen::VectorXd& T) {
  // Arc by arc (link q of arc k = unknown first_unknown_[k] + q, from node first + q to the next; without a
  // module one arc, the whole string), node by node, with each node's two terms in the order of the
  // link-by-link sum T_j e_j at the start, −T_j e_j at the end from zero (for_each_link): the same numbers,
  // without zeroing the array (but for the nodes in no arc) and writing every node of the arcs twice. For
  // arcs in order (arcs_in_order).
  const int n = chain_.num_nodes();
  int covered = 0;
  for (const ArcRange& arc : arcs_) covered += arc.num_nodes();
  if (covered < n) tension_force_.setZero();  // the nodes in no arc
  // Raw pointers in locals, as in links(); T_j e_j carried from one node to the next.
  using CMap = Eigen::Map<const Vec<dim>>;
  const double* const e = e_.data();
  const double* const tension = T.data();
  double* const out = tension_force_.data();
  for (std::size_t k = 0; k < arcs_.size(); ++k) {
    const ArcRange& arc = arcs_[k];
    const int nl = arc.num_links(), u0 = first_unknown_[k];
    Eigen::Map<Vec<dim>> first(out + dim * arc.first);
    if (nl == 0) {
      first.setZero();
      continue;
    }
    // link q of the arc: unknown u0 + q, direction e of link arc.first + q
    const auto te = [&](int q) { return Vec<dim>(tension[u0 + q] * CMap(e + dim * (arc.first + q))); };
    Vec<dim> previous = te(0);
    first = Vec<dim>::Zero() + previous;
    if (arc.closed) first -= te(nl - 1);
    for (int q = 1; q < arc.num_nodes(); ++q) {
      Vec<dim> f = Vec<dim>::Zero() - previous;
      if (q < nl) {
        previous = te(q);
        f += previous;
      }
      Eigen::Map<Vec<dim>>(out + dim * (arc.first + q)) = f;
    }
  }
}

template <int dim>
double StringModel<dim>::evaluate(double t, const Points<dim>& x, const Points<dim>& v) {
  x_ = x;
  v_ = v;
  return evaluate_current(t);
}

template <int dim>
double StringModel<dim>::evaluate_current(double t) {
  const int n = chain_.num_nodes();
  // 1. The module's masses and forces; applied forces; b_i = F_i / m_i for free nodes, the
  //    prescribed acceleration otherwise.
  refresh();
  const NodeState<dim> state{t, x_, v_, m_};
  force_.setZero();
  force_nc_.setZero();
  for (const auto& force : forces_) force->add_force(state, force->conservative() ? force_ : force_nc_);
  // b_i = w_i (F_i + F_nc,i [+ the module's force]) over raw pointers in locals (as in links()); +0
  // stands for F_nc,i without such a force (force_nc()).
  using CMap = Eigen::Map<const Vec<dim>>;
  using Map = Eigen::Map<Vec<dim>>;
  const double *const w = w_.data(), *const f = force_.data();
  const double* const f_nc = force_nc_.cols() ? force_nc_.data() : nullptr;
  const double* const f_module = module_ ? module_force_.data() : nullptr;
  double* const b_of = b_.data();
  for (const FreeRun& run : free_runs_) {
    for (int i = run.node, end = run.node + run.count; i < end; ++i) {
      Vec<dim> sum = CMap(f + dim * i) + (f_nc ? Vec<dim>(CMap(f_nc + dim * i)) : Vec<dim>::Zero());
      if (f_module) sum += CMap(f_module + dim * i);
      Map(b_of + dim * i) = w[i] * sum;
    }
  }
  for (const int i : prescribed_in_arcs_)
    b_.col(i) = prescribed_[static_cast<std::size_t>(path_of_[i])].path->acceleration(t);
  // 2. Link geometry and the tension system.
  if (quadratic_) {
    x_max_ = x_.cwiseAbs().maxCoeff();
    beta2_ = capped_beta2();
    quadratic_->evaluate(x_, v_, force_, force_nc_, b_, alpha_, beta2_);
    tension_force_ = quadratic_->tension_forces();
  } else if (system_) {
    links();
    // Every value and right side is set below (the arcs' diagonals, couplings and right sides) unless
    // bent links, held nodes or excluded (slack) links add to them: only those need the zeroing.
    if (!bends_.empty() || !contacts_.empty() || allows_slack() || system_->has_exclusions()) system_->zero();
    assemble_matrix();
    if (contact_friction_on_) friction_couplings();
    beta2_ = capped_beta2();  // the drift control's position term, capped (capped_beta2)
    if (!contacts_.empty()) constrain_contact_nodes();
    const double two_alpha = 2 * alpha_, half_beta2 = beta2_ * 0.5;  // the products the sum began with
    for_each_link([&](int j, int u, int) {
      const int a = chain_.link_start(j), b = chain_.link_end(j);
      const double h = chain_.link_length(j), l = l_[j];
      const double stab = two_alpha * dx_.col(j).dot(dv_.col(j)) + half_beta2 * (l * l - h * h);
      system_->rhs(u) = -dv_.col(j).squaredNorm() / l - e_.col(j).dot(b_.col(b) - b_.col(a)) - stab / l;
    });
    for (const Bend& bend : bends_) {
      // d²(l⁻ + l⁺)/dt² = e⁺·a_b − e⁻·a_a + |v_b⊥e⁺|²/l⁺ + |v_a⊥e⁻|²/l⁻ = 0, with the same drift control.
      const int j = bend.link, u = link_unknown_[static_cast<std::size_t>(j)];
      if (u < 0) continue;
      const int a = chain_.link_start(j), b = chain_.link_end(j);
      const Vec<dim> em = e_.col(j), ep = bend.e_plus;
      if (bend.circle) {  // d²l/dt² = e⁺·a_b − e⁻·a_a + q (circle_bend)
        const double h = chain_.link_length(j), l = l_[j];
        const double stab = 2 * alpha_ * bend_rate(bend) + beta2_ * 0.5 * (l * l - h * h) / l;
        system_->rhs(u) = -bend.q - (ep.dot(b_.col(b)) - em.dot(b_.col(a))) - stab;
        continue;
      }
      const Vec<dim> va = v_.col(a) - em * em.dot(v_.col(a)), vb = v_.col(b) - ep * ep.dot(v_.col(b));
      const double h = chain_.link_length(j), l = l_[j];
      const double stab = 2 * alpha_ * bend_rate(bend) + beta2_ * 0.5 * (l * l - h * h) / l;
      // |v⊥|²/l with l signed (point_bend_sides); through zero within the floor, where a node passes the point;
      // none for a side measured along its line near the point (its l = d·(x0 − x_a) has no such term).
      const double floor = kBentLinkFloor * h;
      auto turn = [floor](double v2, double part, bool near) {
        return near ? 0.0 : std::abs(part) > floor ? v2 / part : v2 * part / (floor * floor);
      };
      system_->rhs(u) = -turn(va.squaredNorm(), bend.l_minus, bend.near_minus) -
                        turn(vb.squaredNorm(), bend.l_plus, bend.near_plus) - (ep.dot(b_.col(b)) - em.dot(b_.col(a))) - stab;
    }
    if (contact_stuck_) locked_rhs();
    const Eigen::VectorXd& T = solve_tensions(t);
    if (!constraints_.empty()) impose_constraints(t);  // T: the sum with the constraints' share
    if (contact_friction_on_) {
      last_tension_.resize(static_cast<std::size_t>(chain_.num_links()), 0.0);
      for_each_link([&](int j, int u, int) { last_tension_[static_cast<std::size_t>(j)] = T[u]; });
    }
    if (bends_.empty() && arcs_in_order(arcs_, chain_.num_nodes(), chain_.closed())) {
      tension_forces_of_string(T);
    } else {
      tension_force_.setZero();
      for_each_link([&](int j, int u, int) {
        tension_force_.col(chain_.link_start(j)) += T[u] * e_.col(j);
        tension_force_.col(chain_.link_end(j)) -= T[u] * e_.col(j);
      });
    }
    for (const Bend& bend : bends_) {
      const int u = link_unknown_[static_cast<std::size_t>(bend.link)];
      if (u >= 0) tension_force_.col(chain_.link_end(bend.link)) += T[u] * (e_.col(bend.link) - bend.e_plus);
    }
  } else {
    tension_force_.setZero();  // no link in any arc (every node held, or single-node arcs)
  }
  // 3. Accelerations, the supports' reactions and the power of everything not booked in V.
  double power = 0;
  if (module_) external_.setZero();
  const auto prescribed_node = [&](int i) {
    a_.col(i) = b_.col(i);
    // the support's reaction R_i = m a − F − T − (module force); drag on it is applied work too
    auto reaction = reaction_.col(path_of_[i]);
    reaction = (quadratic_ ? Vec<dim>(quadratic_->inertia().col(i)) : Vec<dim>(m_[i] * a_.col(i))) - force_.col(i) - force_nc(i) - tension_force_.col(i);
    if (module_) reaction -= module_force_.col(i);
    power += (reaction + force_nc(i)).dot(v_.col(i));
  };
  if (!quadratic_ && force_nc_.cols() == 0) {
    // A free node's power term is force_nc·v = ±0 here, which leaves the sum as it is (it starts at
    // +0 and is never −0): the free nodes' accelerations in runs, then the prescribed nodes in order.
    const double* const tf = tension_force_.data();
    double* const a_of = a_.data();
    for (const FreeRun& run : free_runs_)
      for (int i = run.node, end = run.node + run.count; i < end; ++i)
        Map(a_of + dim * i) = CMap(b_of + dim * i) + w[i] * CMap(tf + dim * i);
    if (!module_) {
      for (const int i : prescribed_in_arcs_) prescribed_node(i);
    } else {
      // The external force Σ F_i (+ R_i at a prescribed node) over the nodes of the arcs in the order of
      // the nodes, as the loop below sums it: the free runs and the prescribed nodes merged (both in that
      // order). A free node's F_nc + 0 terms are ±0, which leave a sum that is never −0 as it is.
      Vec<dim> external = Vec<dim>::Zero();
      std::size_t p = 0;
      const std::size_t np = prescribed_in_arcs_.size();
      const auto prescribed_external = [&](int i) {
        prescribed_node(i);
        external += force_.col(i) + force_nc(i) + Vec<dim>(reaction_.col(path_of_[i]));
      };
      for (const FreeRun& run : free_runs_) {
        for (; p < np && prescribed_in_arcs_[p] < run.node; ++p) prescribed_external(prescribed_in_arcs_[p]);
        for (int i = run.node, end = run.node + run.count; i < end; ++i) external += CMap(f + dim * i);
      }
      for (; p < np; ++p) prescribed_external(prescribed_in_arcs_[p]);
      external_ = external;
    }
  } else {
    for (int i = 0; i < n; ++i) {
      if (arc_of_[i] < 0) continue;
      if (path_of_[i] < 0) {
        a_.col(i) = quadratic_ ? Vec<dim>(quadratic_->accelerations().col(i)) : Vec<dim>(b_.col(i) + w_[i] * tension_force_.col(i));
        power += force_nc(i).dot(v_.col(i));
      } else {
        prescribed_node(i);
      }
      if (module_)
        external_ += force_.col(i) + force_nc(i) + (path_of_[i] >= 0 ? Vec<dim>(reaction_.col(path_of_[i])) : Vec<dim>::Zero());
    }
  }
  if (module_ && !bends_.empty()) external_ += bend_reaction();  // the points the links are bent over
  if (!contacts_.empty()) {
    // A held node moves with w_i P (its force) + c_i n; the contact force N n is what that takes:
    // N = m_i (c_i − n·b_i) − n·(tension force), b_i its unconstrained acceleration.
    contact_force_.resize(contacts_.size());
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const NodeContact<dim>& c = contacts_[k];
      const int i = c.node;
      const double fn = c.normal.dot(tension_force_.col(i));
      a_.col(i) -= w_[i] * fn * c.normal;
      const double target = c.normal.dot(b_.col(i));
      contact_force_[k] = m_[i] * (target - contact_bn_[k]) - fn;
      external_ += contact_force_[k] * c.normal;
    }
    if (contact_friction_on_) contact_friction_forces();
  }
  return power;
}

template <int dim>
void StringModel<dim>::rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
  unpack_state(t, y);
  write_rates(evaluate_current(t), ydot);
}

template <int dim>
void StringModel<dim>::write_rates(double power, Eigen::Ref<Eigen::VectorXd> ydot) {
  const int voff = dim * num_free_;
  for (const FreeRun& run : free_runs_) {
    ydot.segment(dim * run.slot, dim * run.count) = Eigen::Map<const Eigen::VectorXd>(v_.col(run.node).data(), dim * run.count);
    ydot.segment(voff + dim * run.slot, dim * run.count) =
        Eigen::Map<const Eigen::VectorXd>(a_.col(run.node).data(), dim * run.count);
  }
  ydot[work_index()] = power;
  if (module_) module_->ledger_rates(*this, ydot.segment(work_index() + 1, num_ledgers_));
}

template <int dim>
void StringModel<dim>::events(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g) {
  if (!module_) return;
  unpack_state(t, y);
  if (module_->events_need_tensions())
    evaluate_current(t);
  else
    refresh();
  module_->events(*this, g);
}

template <int dim>
double StringModel<dim>::speed_scale() const {
  const double ell = chain_.length();
  double v2 = uniform_field().norm() * ell;
  for (int i = 0; i < chain_.num_nodes(); ++i) v2 = std::max(v2, chain_.velocities().col(i).squaredNorm());
  return v2 > 0 ? std::sqrt(v2) : ell;
}

template <int dim>
Eigen::VectorXd StringModel<dim>::state_scale() const {
  if (!module_) return {};
  const double ell = chain_.length();
  const double speed = speed_scale();
  const double mass = chain_.density() * ell;
  Eigen::VectorXd scale(size());
  const int voff = dim * num_free_;
  scale.head(voff).setConstant(ell);
  scale.segment(voff, voff).setConstant(speed);
  scale[work_index()] = mass * speed * speed;
  scale.tail(num_ledgers_) = module_->ledger_scale(mass, speed, ell);
  return scale;
}

template <int dim>
double StringModel<dim>::project(double t) {
  if (!system_) return 0.0;
  project_positions(t);
  return quadratic_ ? 0.0 : project_velocities(t);
}

template <int dim>
void StringModel<dim>::project_positions(double t) {
  for (const auto& p : prescribed_) {
    x_.col(p.node) = p.path->position(t);
    v_.col(p.node) = p.path->velocity(t);
  }
  if (quadratic_) return quadratic_->project(t, x_, v_);
  project_link_lengths(t);
  if (module_) {  // the module's constraints at these positions (refresh() may not have run yet)
    constraints_.clear();
    module_->node_constraints(*this, constraints_);
  }
  if (constraints_.empty()) return;
  // The module's constraints (a kink's compatibility): Newton steps along their gradients projected
  // onto the links' rates, each followed by the links' projection, until C is at its round-off
  // (|C| ~ ε |x|) or no longer halves.
  double c_previous = INFINITY;
  for (int iteration = 0;; ++iteration) {
    refresh();
    const double c_violation = constraint_violation();
    if (c_violation <= kRoundoffUlps * std::numeric_limits<double>::epsilon() * x_max_ ||
        (c_violation < 1e3 * constraint_tolerance() * h_min_ && c_violation > 0.5 * c_previous))
      break;
    if (iteration == kProjectionIterations || !std::isfinite(c_violation))
      throw NumericalError(fmt::format("at t = {:.9g} s the kink's arms cannot be brought to meet: after {} projection "
                                       "steps they are still {:.3g} m apart",
                                       t, iteration, c_violation),
                           t);
    c_previous = c_violation;
    Eigen::VectorXd target(static_cast<Eigen::Index>(constraints_.size()));
    for (std::size_t k = 0; k < constraints_.size(); ++k) target[static_cast<Eigen::Index>(k)] = constraints_[k].value;
    links();
    system_->zero();
    assemble_matrix();
    exclude_slack_links();
    correct_constraints(t, target, x_);
    project_link_lengths(t);  // the links again (their violation is second order in the step)
    // A slack link the correction carried past its length is taut again (its tension solve may release
    // it): the projection holds it at its length, as it holds the taut ones.
    if (num_slack_ > 0) {
      links();
      bool caught = false;
      for (int j = 0; j < chain_.num_links(); ++j)
        if (link_unknown_[static_cast<std::size_t>(j)] >= 0 && link_slack(j) && l_[j] > chain_.link_length(j)) {
          set_slack(j, false);
          caught = true;
        }
      if (caught) project_link_lengths(t);
    }
  }
}

template <int dim>
void StringModel<dim>::project_link_lengths(double t) {
  // Newton's method for g_j(x) = |Δx_j| − h_j = 0 along δx = W Gᵀ ν: the matrix is the tension
  // matrix A = −G W Gᵀ, so A ν = g gives the smallest mass-weighted correction.
  auto correct = [&](Points<dim>& target, const Eigen::VectorXd& nu) { add_link_responses(target, nu); };
  double violation = 0, previous = INFINITY, roundoff = 0;
  for (int iteration = 0;; ++iteration) {
    double gap_violation = 0;
    if (!contacts_.empty()) {
      // The held nodes back on their surfaces first (a correction along the links' directions moves
      // a node on a cylinder off it at second order), then the links.
      refresh();
      gap_violation = place_contact_nodes();
      refresh();
    }
    links();
    const double tolerance = constraint_tolerance();
    roundoff = tolerance;
    violation = gap_violation;
    for_each_link([&](int j, int, int) {
      if (!link_slack(j)) violation = std::max(violation, std::abs(l_[j] - chain_.link_length(j)) / chain_.link_length(j));
    });
    // Converged; or stalled at a few times the round-off level (Newton no longer halves it).
    if (violation <= tolerance || (violation < 1e3 * tolerance && violation > 0.5 * previous)) break;
    if (iteration == kProjectionIterations || !std::isfinite(violation))
      throw NumericalError(fmt::format("at t = {:.9g} s the links cannot be projected onto their lengths: after {} "
                                       "projection steps a link is still off by {:.3g} of its length (tolerance "
                                       "{:.3g}: the round-off level of the coordinates, at least 1e-14)",
                                       t, iteration, violation, roundoff),
                           t);
    previous = violation;
    system_->zero();
    assemble_matrix();
    for_each_link([&](int j, int u, int) { system_->rhs(u) = l_[j] - chain_.link_length(j); });
    exclude_slack_links();
    correct(x_, system_->solve(t));
  }
}

template <int dim>
double StringModel<dim>::constraint_violation() const {
  double c = 0;
  for (const NodeConstraint<dim>& k : constraints_) c = std::max(c, std::abs(k.value));
  return c;
}

template <int dim>
Eigen::VectorXd StringModel<dim>::project_onto_links(double t, Points<dim>& z) {
  for_each_link([&](int j, int u, int) {
    system_->rhs(u) = e_.col(j).dot(z.col(chain_.link_end(j)) - z.col(chain_.link_start(j)));
  });
  for (const Bend& bend : bends_) {
    const int u = link_unknown_[static_cast<std::size_t>(bend.link)];
    if (u >= 0)
      system_->rhs(u) = bend.e_plus.dot(z.col(chain_.link_end(bend.link))) -
                        e_.col(bend.link).dot(z.col(chain_.link_start(bend.link)));
  }
  exclude_slack_links();
  Eigen::VectorXd nu = system_->solve(t);
  add_link_responses(z, nu);
  return nu;
}

template <int dim>
double StringModel<dim>::correct_constraints(double t, const Eigen::VectorXd& target, Points<dim>& field) {
  const int K = static_cast<int>(constraints_.size()), n = chain_.num_nodes();
  std::vector<Points<dim>> z(static_cast<std::size_t>(K));
  std::vector<Eigen::VectorXd> nu(static_cast<std::size_t>(K));
  Eigen::MatrixXd M(K, K);
  for (int k = 0; k < K; ++k) {
    const NodeConstraint<dim>& c = constraints_[static_cast<std::size_t>(k)];
    Points<dim>& zk = z[static_cast<std::size_t>(k)];
    zk = Points<dim>::Zero(dim, n);
    for (std::size_t q = 0; q < c.nodes.size(); ++q) {
      const int i = c.nodes[q];
      if (arc_of_[i] >= 0 && path_of_[i] < 0) zk.col(i) += w_[i] * c.gradient.col(static_cast<Eigen::Index>(q));
    }
    nu[static_cast<std::size_t>(k)] = project_onto_links(t, zk);
  }
  for (int l = 0; l < K; ++l) {
    const NodeConstraint<dim>& c = constraints_[static_cast<std::size_t>(l)];
    for (int k = 0; k < K; ++k) {
      double m = 0;
      for (std::size_t q = 0; q < c.nodes.size(); ++q)
        m += c.gradient.col(static_cast<Eigen::Index>(q)).dot(z[static_cast<std::size_t>(k)].col(c.nodes[q]));
      M(l, k) = m;
    }
  }
  const Eigen::VectorXd mu = M.fullPivLu().solve(-target);
  if (!mu.allFinite())
    throw NumericalError(fmt::format("at t = {:.9g} s the kink's constraint cannot be met: its nodes cannot move", t), t);
  // The supports' work: of the links' share (ν_k) and of the constraints' own impulses μ_k ∂C_k/∂x_i at
  // prescribed nodes, which their supports take.
  double work = 0;
  for (int k = 0; k < K; ++k) {
    field += mu[k] * z[static_cast<std::size_t>(k)];
    work += mu[k] * supports_work(nu[static_cast<std::size_t>(k)]);
    const NodeConstraint<dim>& c = constraints_[static_cast<std::size_t>(k)];
    for (std::size_t q = 0; q < c.nodes.size(); ++q) {
      const int i = c.nodes[q];
      if (arc_of_[i] >= 0 && path_of_[i] >= 0) work -= mu[k] * c.gradient.col(static_cast<Eigen::Index>(q)).dot(v_.col(i));
    }
  }
  return work;
}

template <int dim>
double StringModel<dim>::supports_work(const Eigen::VectorXd& nu) const {
  double work = 0;
  for_each_link([&](int j, int u, int) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    if (path_of_[a] >= 0) work += nu[u] * e_.col(j).dot(v_.col(a));
    if (path_of_[b] >= 0) {
      const Bend* bend = bends_.empty() ? nullptr : bend_of(j);
      work -= nu[u] * (bend ? Vec<dim>(bend->e_plus) : Vec<dim>(e_.col(j))).dot(v_.col(b));
    }
  });
  return work;
}

template <int dim>
void StringModel<dim>::impose_constraints(double t) {
  // The constraints' rows bordering the tension system: T = T0 + Σ μ_k Y_k, Y_k the tensions that a
  // unit multiplier's forces ∂C_k/∂x_i ask of the links, and μ from C̈_l + 2α Ċ_l + β² C_l = 0 with
  // the accelerations they give (docs/model.md §2.5, "The arms meet").
  const int K = static_cast<int>(constraints_.size()), N = system_->size();
  const Eigen::VectorXd rhs0 = system_->rhs_vector(), T0 = system_->solution();
  auto is_free = [&](int i) { return arc_of_[i] >= 0 && path_of_[i] < 0; };
  auto unknown = [&](int j) { return j >= 0 ? link_unknown_[static_cast<std::size_t>(j)] : -1; };
  auto end_direction = [&](int j) -> Vec<dim> {
    const Bend* bend = bends_.empty() ? nullptr : bend_of(j);
    return bend ? bend->e_plus : Vec<dim>(e_.col(j));
  };
  // The links' force on node i for tensions T.
  auto tension_on = [&](int i, const Eigen::VectorXd& T) {
    Vec<dim> f = Vec<dim>::Zero();
    const auto [jm, jp] = node_links(i);
    if (unknown(jp) >= 0) f += T[unknown(jp)] * e_.col(jp);
    if (unknown(jm) >= 0) f -= T[unknown(jm)] * end_direction(jm);
    return f;
  };
  // Constraint k's unit force on node i (zero where it has none).
  auto unit_force = [&](int k, int i) {
    const NodeConstraint<dim>& c = constraints_[static_cast<std::size_t>(k)];
    Vec<dim> f = Vec<dim>::Zero();
    for (std::size_t q = 0; q < c.nodes.size(); ++q)
      if (c.nodes[q] == i) f += c.gradient.col(static_cast<Eigen::Index>(q));
    return f;
  };
  std::vector<Eigen::VectorXd> drhs(static_cast<std::size_t>(K), Eigen::VectorXd::Zero(N)), Y(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) {
    Eigen::VectorXd& r = drhs[static_cast<std::size_t>(k)];
    for (const int i : constraints_[static_cast<std::size_t>(k)].nodes) {
      if (!is_free(i)) continue;
      const Vec<dim> db = w_[i] * unit_force(k, i);
      const auto [jm, jp] = node_links(i);
      // row j: ... = −e_end·b_end + e_j·b_start
      if (unknown(jp) >= 0) r[unknown(jp)] += e_.col(jp).dot(db);
      if (unknown(jm) >= 0) r[unknown(jm)] -= end_direction(jm).dot(db);
    }
    for (int u = 0; u < N; ++u) {
      if (system_->excluded(u)) r[u] = 0;
      system_->rhs(u) = r[u];
    }
    Y[static_cast<std::size_t>(k)] = system_->solve(t);
  }
  // μ from the constraints' rows.
  Eigen::MatrixXd M(K, K);
  Eigen::VectorXd residual(K);
  for (int l = 0; l < K; ++l) {
    const NodeConstraint<dim>& c = constraints_[static_cast<std::size_t>(l)];
    double rate = 0, row = 0;
    for (std::size_t q = 0; q < c.nodes.size(); ++q) {
      const int i = c.nodes[q];
      const Vec<dim> g = c.gradient.col(static_cast<Eigen::Index>(q));
      rate += g.dot(v_.col(i));
      row += g.dot(is_free(i) ? Vec<dim>(b_.col(i) + w_[i] * tension_on(i, T0)) : Vec<dim>(b_.col(i)));
      for (int k = 0; k < K; ++k)
        M(l, k) = (q == 0 ? 0.0 : M(l, k)) +
                  (is_free(i) ? g.dot(w_[i] * (unit_force(k, i) + tension_on(i, Y[static_cast<std::size_t>(k)]))) : 0.0);
    }
    residual[l] = row + c.curvature + 2 * alpha_ * rate + beta2_ * c.value;
  }
  constraint_multipliers_ = M.fullPivLu().solve(-residual);
  if (!constraint_multipliers_.allFinite())
    throw RecoverableError(fmt::format("at t = {:.9g} s the kink's constraint has no multiplier", t));
  Eigen::VectorXd rhs = rhs0;
  for (int k = 0; k < K; ++k) rhs += constraint_multipliers_[k] * drhs[static_cast<std::size_t>(k)];
  for (int u = 0; u < N; ++u) system_->rhs(u) = rhs[u];
  system_->solve(t);
  // The multipliers' forces on the nodes: in the module's forces (a support's reaction takes the
  // share on a prescribed node) and in the free nodes' accelerations.
  for (int k = 0; k < K; ++k) {
    const NodeConstraint<dim>& c = constraints_[static_cast<std::size_t>(k)];
    for (std::size_t q = 0; q < c.nodes.size(); ++q) {
      const int i = c.nodes[q];
      const Vec<dim> f = constraint_multipliers_[k] * c.gradient.col(static_cast<Eigen::Index>(q));
      module_force_.col(i) += f;
      if (is_free(i)) b_.col(i) += w_[i] * f;
    }
  }
}

template <int dim>
double StringModel<dim>::project_velocities(double t) {
  auto correct = [&](Points<dim>& target, const Eigen::VectorXd& nu) { add_link_responses(target, nu); };
  // Velocities: one linear projection onto e_j·Δv_j = 0 (held nodes: onto n·v = 0 first, then with
  // their responses w_i P: the mass-weighted projection onto both).
  for (const NodeContact<dim>& c : contacts_) v_.col(c.node) -= c.normal.dot(v_.col(c.node)) * c.normal;
  links();
  system_->zero();
  assemble_matrix();
  for_each_link([&](int j, int u, int) { system_->rhs(u) = e_.col(j).dot(dv_.col(j)); });
  for (const Bend& bend : bends_) {
    const int u = link_unknown_[static_cast<std::size_t>(bend.link)];
    if (u >= 0) system_->rhs(u) = bend_rate(bend);
  }
  exclude_slack_links();
  const Eigen::VectorXd nu = system_->solve(t);
  correct(v_, nu);
  double work = supports_work(nu);
  if (module_) {
    constraints_.clear();
    module_->node_constraints(*this, constraints_);
  }
  if (constraints_.empty()) return work;
  // The module's constraints: Ċ_k = Σ ∂C_k/∂x_i · v_i = 0 as well (the mass-weighted projection onto
  // both: the links' projection of the constraints' gradients, combined).
  // As for the positions, a rate at its round-off (ε Σ |∂C/∂x_i| |v_i|) is left as it is.
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(constraints_.size()));
  bool off = false;
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    double scale = 0;
    for (std::size_t q = 0; q < constraints_[k].nodes.size(); ++q) {
      const Vec<dim> g = constraints_[k].gradient.col(static_cast<Eigen::Index>(q)), vi = v_.col(constraints_[k].nodes[q]);
      rate[static_cast<Eigen::Index>(k)] += g.dot(vi);
      scale += g.norm() * vi.norm();
    }
    off = off || std::abs(rate[static_cast<Eigen::Index>(k)]) > kRoundoffUlps * std::numeric_limits<double>::epsilon() * scale;
  }
  if (off) work += correct_constraints(t, rate, v_);
  return work;
}

template <int dim>
void StringModel<dim>::start_impulses(double t0) {
  // Unilateral links at the start (docs/model.md §9, "The start"): the positions onto the taut links'
  // lengths as always; the velocities by the snap's law, as if the string snapped taut at t0. A link whose
  // initial rate shortens it goes slack (P = 0, it flies freely), a lengthening one takes the impulse of
  // the complementarity problem with the scene's restitution, and the supports' and obstacles' impulses
  // are what they are at a snap. A rate below kSeparation of the fastest node is the round-off of a
  // compatible start: it is not a separation, and the bilateral projection that follows (slack links out)
  // takes it to zero as with slack = "stop".
  project_positions(t0);
  double speed = 0;
  for (int i = 0; i < chain_.num_nodes(); ++i)
    if (in_arc(i)) speed = std::max(speed, v_.col(i).norm());
  for (const NodeContact<dim>& c : contacts_) v_.col(c.node) -= c.normal.dot(v_.col(c.node)) * c.normal;
  const SnapResult r = link_impulses(t0, options_.snap_restitution, speed);
  impulsive_start_.dissipated += r.dissipated;
  project_velocities(t0);
}

template <int dim>
void StringModel<dim>::set_rotation_velocities() {
  for (int i = 0; i < chain_.num_nodes(); ++i)
    if (in_arc(i) && path_of_[i] < 0) v_.col(i) = options_.rotation->template velocity<dim>(x_.col(i));
}

template <int dim>
void StringModel<dim>::set_sliding_velocities(double speed) {
  // The string sliding along itself (docs/scenes.md, "The velocity kinds"). Along the direction of
  // motion each node has an incoming direction a (the string before it) and an outgoing one b, turned
  // from a by φ; the node moves at |speed| along m, turned from a by ψ ∈ [0, φ/2] towards b. The link
  // from node k to node k + 1 then lengthens at |speed| (cos ψ_{k+1} − cos(φ_k − ψ_k)): ≥ 0 as long as
  // ψ_{k+1} ≤ φ_k − ψ_k. So ψ_{k+1} = min(φ_{k+1}/2, φ_k − ψ_k): the bisector (the central difference,
  // exact on a circle) wherever the turn does not grow along the motion, else the largest ψ that keeps
  // that link at its length; at a corner between straight stretches ψ = 0, along the incoming link, and
  // the outgoing link lengthens at |speed| (1 − cos θ): the start's snap turns the corner's node, the
  // moving kink of a string sliding through a sharp corner. A link bent over a point gives its ends
  // the directions of its two sides (the turn at the point is the point's): each side slides along its
  // own line and the bent link keeps its length exactly.
  const Points<dim>& x = chain_.positions();
  auto direction = [&](int j, bool at_end) -> Vec<dim> {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    const Bend* bend = bends_.empty() ? nullptr : bend_of(j);
    const Vec<dim> d = bend != nullptr && !bend->circle
                           ? (at_end ? Vec<dim>(x.col(b) - bend->point) : Vec<dim>(bend->point - x.col(a)))
                           : Vec<dim>(x.col(b) - x.col(a));
    const double norm = d.norm();
    if (!(norm > 0))
      throw InputError(fmt::format("velocity.kind = \"tangential\": the string's direction at node {} is undefined "
                                   "(coincident nodes)", at_end ? b : a));
    return d / norm;
  };
  const double sense = speed < 0 ? -1.0 : 1.0;
  for (const ArcRange& arc : arcs_) {
    const int K = arc.num_nodes();
    if (K < 2) continue;
    // In the order of motion: node_of(k), its incoming a_k and outgoing b_k (unit), turn φ_k.
    auto node_of = [&](int k) { return speed < 0 ? arc.last - k : arc.first + k; };
    Points<dim> in(dim, K), out(dim, K);
    Eigen::VectorXd phi(K), psi(K);
    for (int k = 0; k < K; ++k) {
      const int i = node_of(k);
      const bool has_before = arc.closed || i > arc.first, has_after = arc.closed || i < arc.last;
      const int before = i == arc.first ? arc.last : i - 1;  // the link ending at i (closed: wraps)
      // the link before node i along s ends at i; the link after starts at i
      // An end of an open string has one link: its direction serves before and after.
      const Vec<dim> along_before = has_before ? direction(before, true) : direction(i, false);
      const Vec<dim> along_after = has_after ? direction(i, false) : along_before;
      in.col(k) = sense * (speed < 0 ? along_after : along_before);
      out.col(k) = sense * (speed < 0 ? along_before : along_after);
      phi[k] = 2 * std::atan2((in.col(k) - out.col(k)).norm(), (in.col(k) + out.col(k)).norm());
      psi[k] = 0.5 * phi[k];
    }
    if (arc.closed) {
      // A loop has no first node: sweep from its sharpest turn until a sweep changes nothing.
      Eigen::Index k0 = 0;
      phi.maxCoeff(&k0);
      for (int pass = 0; pass < 4; ++pass) {
        bool changed = false;
        for (int step = 1; step <= K; ++step) {
          const int k = static_cast<int>((k0 + step) % K), prev = (k + K - 1) % K;
          const double next = std::min(0.5 * phi[k], phi[prev] - psi[prev]);
          changed = changed || next != psi[k];
          psi[k] = next;
        }
        if (!changed) break;
      }
    } else {
      psi[0] = 0;  // the first node: only its outgoing link (a = b)
      for (int k = 1; k < K; ++k) psi[k] = std::min(0.5 * phi[k], phi[k - 1] - psi[k - 1]);
    }
    for (int k = 0; k < K; ++k) {
      const double s = std::sin(phi[k]);
      Vec<dim> m = in.col(k);
      if (psi[k] > 0 && s > 0) m = (std::sin(phi[k] - psi[k]) * in.col(k) + std::sin(psi[k]) * out.col(k)) / s;
      chain_.velocities().col(node_of(k)) = std::abs(speed) * m.normalized();
    }
  }
  v_ = chain_.velocities();
}

template <int dim>
Eigen::VectorXd StringModel<dim>::projected_state(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  unpack_state(t, y);
  // slack = allow: a frame inside a step comes before the step's end, where accept_step declares slack the taut
  // links the tensions released and that have shortened. At the frame such a link is still flagged taut, and
  // projecting onto its length put it back there: a node flying free drawn back along the released link, the
  // frame's K + V off by the work that takes (a chain's top driven down, the node below it flying after a snap:
  // −0.069 J in a frame at 0.16 s, docs/model.md §9 "Frames inside a step"). The frame leaves such links free,
  // as the step's end will; their flags are restored for the run.
  // The flags are restored however the projection ends (it throws when it does not converge).
  struct Restore {
    StringModel& model;
    std::vector<int> freed;
    ~Restore() {
      for (const int j : freed) model.set_slack(j, false);
    }
  } restore{*this, {}};
  if (allows_slack() && system_ && !quadratic_)
    for (int j = 0; j < chain_.num_links(); ++j) {
      if (link_slack(j) || link_unknown_[static_cast<std::size_t>(j)] < 0) continue;
      const double h = chain_.link_length(j);
      if (goes_slack((h - current_length(j)) / h, kSlackGap, link_tension(j),
                     any_released_ && released_[static_cast<std::size_t>(j)])) {
        set_slack(j, true);
        restore.freed.push_back(j);
      }
    }
  refresh();
  project(t);
  return pack(y.tail(1 + num_ledgers_));
}

template <int dim>
double StringModel<dim>::make_consistent(double t0) {
  x_ = chain_.positions();
  v_ = chain_.velocities();
  for (const auto& p : prescribed_) {
    x_.col(p.node) = p.path->position(t0);
    v_.col(p.node) = p.path->velocity(t0);
  }
  for (int j = 0; j < chain_.num_links(); ++j)
    // (a link made slack by an earlier call's start impulses has its offset: it went slack at full length)
    if (link_slack(j) && slack_offset_[static_cast<std::size_t>(j)] == 0 &&
        !(current_length(j) < (1 - kSlackGap) * chain_.link_length(j)))
      throw InputError(fmt::format("link {} is declared slack but is not shorter than its length {:g} m",
                                   j, chain_.link_length(j)));
  const Points<dim> x_start = x_;
  Points<dim> v_start = v_;
  double K_start = 0;
  try {
    refresh();
    if (options_.rotation && system_) {
      // A rigid rotation (StringModelOptions::rotation) is the rotation of the projected shape: the positions onto
      // the links' lengths first, then v = ω × (x − c) there. It is the scene's velocities the start's jump is
      // measured from, and it keeps every link's length: the start's projection (or snap) below changes it by
      // round-off (the positions' projection again, a no-op now).
      project_positions(t0);
      set_rotation_velocities();
      refresh();
      v_start = v_;
      // Once: the later calls (the solver's start calls make_consistent again on the scene's consistent state) start
      // from the velocities this start left; setting the rotation again would book its jump once more (a fixed end
      // off the centre: the start's ΔK twice, −4.78 instead of −2.39 J; review).
      options_.rotation.reset();
    }
    K_start = kinetic_energy();
    if (allows_slack() && system_ && !quadratic_) {
      start_impulses(t0);
    } else {
      project(t0);
    }
    refresh();
  } catch (const RecoverableError& e) {
    throw InputError(fmt::format("the initial shape is degenerate: {}", e.what()));
  } catch (const NumericalError& e) {
    throw InputError(fmt::format("the initial shape cannot be fitted to the link lengths: {} (are the fixed or "
                                 "driven ends further apart than the string is long?)",
                                 e.what()));
  }
  chain_.positions() = x_;
  chain_.velocities() = v_;
  double moved = 0;
  for (int i = 0; i < chain_.num_nodes(); ++i) {
    if (!in_arc(i)) continue;
    moved = std::max(moved, (x_.col(i) - x_start.col(i)).norm());
    impulsive_start_.max_speed_change =
        std::max(impulsive_start_.max_speed_change, (v_.col(i) - v_start.col(i)).norm());
    impulsive_start_.speed_scale =
        std::max({impulsive_start_.speed_scale, v_.col(i).norm(), v_start.col(i).norm()});
  }
  impulsive_start_.kinetic_energy += kinetic_energy() - K_start;
  return moved;
}

template <int dim>
bool StringModel<dim>::start_module(double t0, Eigen::Ref<Eigen::VectorXd> ledger) {
  if (!module_ || !module_->start(*this, t0, ledger)) return false;
  chain_.positions() = x_;
  chain_.velocities() = v_;
  return true;
}

template <int dim>
Eigen::VectorXd StringModel<dim>::pack(const Eigen::Ref<const Eigen::VectorXd>& ledgers) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(size());
  const int voff = dim * num_free_;
  for (int i = 0; i < chain_.num_nodes(); ++i) {
    const int k = slot_[i];
    if (k < 0) continue;
    y.template segment<dim>(dim * k) = x_.col(i);
    y.template segment<dim>(voff + dim * k) = v_.col(i);
  }
  y.tail(1 + num_ledgers_) = ledgers;
  return y;
}

template <int dim>
Eigen::VectorXd StringModel<dim>::state_from_chain() const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(size());
  const int voff = dim * num_free_;
  for (int i = 0; i < chain_.num_nodes(); ++i) {
    const int k = slot_[i];
    if (k < 0) continue;
    y.template segment<dim>(dim * k) = chain_.positions().col(i);
    y.template segment<dim>(voff + dim * k) = chain_.velocities().col(i);
  }
  return y;
}

template <int dim>
double StringModel<dim>::kinetic_energy() const {
  if (quadratic_) return quadratic_->kinetic_energy(v_);
  double K = 0;
  for (int i = 0; i < chain_.num_nodes(); ++i)
    if (in_arc(i)) K += 0.5 * m_[i] * v_.col(i).squaredNorm();
  return K;
}

template <int dim>
Vec<dim> StringModel<dim>::momentum() const {
  Vec<dim> p = Vec<dim>::Zero();
  for (int i = 0; i < chain_.num_nodes(); ++i)
    if (in_arc(i)) p += m_[i] * v_.col(i);
  return p;
}

template <int dim>
Vec<dim> StringModel<dim>::support_reaction() const {
  Vec<dim> r = Vec<dim>::Zero();
  for (Eigen::Index k = 0; k < reaction_.cols(); ++k) r += reaction_.col(k);
  return r;
}

template <int dim>
double StringModel<dim>::potential_energy(const Eigen::Ref<const Eigen::VectorXd>& ledger) const {
  const NodeState<dim> state{0.0, x_, v_, m_};
  double V = 0;
  for (const auto& force : forces_)
    if (force->conservative()) V += force->potential(state);
  if (module_) V += module_->potential_correction(*this, ledger);
  return V;
}

template <int dim>
typename StringModel<dim>::Snapshot StringModel<dim>::snapshot(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                                                                    Eigen::VectorXd* rates) {
  Snapshot s;
  s.t = t;
  unpack_state(t, y);
  s.power = evaluate_current(t);
  if (rates) {
    rates->resize(size());
    write_rates(s.power, *rates);
  }
  s.x = x_;
  s.v = v_;
  s.tension = Eigen::VectorXd::Constant(chain_.num_links(), std::numeric_limits<double>::quiet_NaN());
  if (quadratic_) {
    s.tension = quadratic_->link_tensions();
  } else if (system_) {
    const Eigen::VectorXd& T = system_->solution();
    for_each_link([&](int j, int u, int) { s.tension[j] = T[u]; });
  }
  const auto ledger = y.tail(num_ledgers_);
  s.kinetic = kinetic_energy();
  s.potential = potential_energy(ledger);
  s.momentum = momentum();
  for (int i = 0; i < chain_.num_nodes(); ++i)
    if (in_arc(i)) s.moving_mass += m_[i];
  s.work = y[work_index()];
  if (quadratic_) {
    s.max_violation = quadratic_->max_constraint_violation(x_);
    s.max_rate_violation = quadratic_->max_rate_violation(x_, v_);
  } else {
    for_each_link([&](int j, int, int) {
      if (link_slack(j)) return;
      s.max_violation = std::max(s.max_violation, std::abs(l_[j] - chain_.link_length(j)) / chain_.link_length(j));
      const bool bent = std::any_of(bends_.begin(), bends_.end(), [j](const Bend& b) { return b.link == j; });
      if (!bent) s.max_rate_violation = std::max(s.max_rate_violation, std::abs(e_.col(j).dot(dv_.col(j))));
    });
    for (const Bend& bend : bends_) s.max_rate_violation = std::max(s.max_rate_violation, std::abs(bend_rate(bend)));
  }
  s.support = support_reaction();
  for (const auto& p : prescribed_) {
    s.end_reactions.push_back(reaction_.col(path_of_[static_cast<std::size_t>(p.node)]));
    double T = std::numeric_limits<double>::quiet_NaN();
    for_each_link([&](int j, int, int) {
      if (chain_.link_start(j) == p.node || chain_.link_end(j) == p.node) T = s.tension[j];
    });
    // No link of an arc at the node: a front sits next to it (e.g. at the fixed end), and the
    // tension there is the front's end tension, carried by its partial link.
    if (std::isnan(T) && module_)
      if (const std::optional<double> front = module_->front_tension_at(*this, p.node)) T = *front;
    s.end_tensions.push_back(T);
  }
  const PhysicalScales scales = physical_scales();
  s.tension_scale = scales.tension;
  s.energy_scale = scales.energy;
  if (module_) {
    ModuleLedger<dim>& extra = s;
    const Vec<dim> prescribed_support = s.support;
    module_->fill(*this, ledger, extra);
    s.support += prescribed_support;
  }
  return s;
}

template <int dim>
double StringModel<dim>::max_constraint_violation(double t, const Eigen::Ref<const Eigen::VectorXd>& y) const {
  return worst_constraint_violation(t, y).relative;
}

template <int dim>
typename StringModel<dim>::ConstraintViolation StringModel<dim>::worst_constraint_violation(
    double t, const Eigen::Ref<const Eigen::VectorXd>& y) const {
  ConstraintViolation worst;
  if (quadratic_) {
    Points<dim> x, v;
    unpack(t, y, x, v);
    worst.relative = quadratic_->max_constraint_violation(x);
    return worst;
  }
  auto position = [&](int i) -> Vec<dim> {
    const int k = slot_[i];
    if (k >= 0) return y.template segment<dim>(dim * k);
    return prescribed_[static_cast<std::size_t>(path_of_[i])].path->position(t);
  };
  for_each_link([&](int j, int, int) {
    if (link_slack(j)) return;
    const double h = chain_.link_length(j);
    const Vec<dim> a = position(chain_.link_start(j)), b = position(chain_.link_end(j));
    double l = (b - a).norm();
    for (const Bend& bend : bends_) {  // a bent link's length runs over its point (signed parts: point_bend_sides)
      if (bend.link != j) continue;
      if (bend.circle) {  // its straight parts and its arc on the circle
        l = circle_bend(bend, position).l;
      } else {
        const PointBendSides sides = point_bend_sides(bend, position, false);
        l = sides.l_minus + sides.l_plus;
      }
    }
    if (std::abs(l - h) / h > worst.relative) worst = {std::abs(l - h) / h, j, l};
  });
  return worst;
}

template <int dim>
typename StringModel<dim>::PhysicalScales StringModel<dim>::physical_scales() const {
  const double lambda = chain_.density(), ell = chain_.length();
  const Vec<dim> g = uniform_field();
  double v2_max = 0, loads = 0, a_driven = 0;
  for (int i = 0; i < chain_.num_nodes(); ++i) {
    if (!in_arc(i)) continue;
    v2_max = std::max(v2_max, v_.col(i).squaredNorm());
    if (path_of_[i] < 0)
      loads += (force_.col(i) + force_nc(i) - m_[i] * g).norm();
    else
      a_driven = std::max(a_driven, b_.col(i).norm());  // the path's acceleration
  }
  const double statics = lambda * g.norm() * ell + loads;
  return {statics + lambda * (v2_max + ell * a_driven), ell * statics};
}

template <int dim>
std::optional<SlackReport> StringModel<dim>::find_slack(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (!system_) return std::nullopt;
  unpack_state(t, y);
  evaluate_current(t);
  const Eigen::VectorXd T = quadratic_ ? quadratic_->link_tensions() : system_->solution();
  // A string with no weight, load, speed or driver has zero exact tension: whatever the solve gives
  // is round-off, never slack.
  const double physical = physical_scales().tension;
  if (!(physical > 0)) return std::nullopt;
  const double scale = std::max(T.cwiseAbs().maxCoeff(), physical);
  int worst = -1;
  for_each_link([&](int j, int u, int) {
    if (worst < 0 || T[u] < T[link_unknown_[static_cast<std::size_t>(worst)]]) worst = j;
  });
  const double T_worst = T[link_unknown_[static_cast<std::size_t>(worst)]];
  if (!(T_worst < -options_.slack_tolerance * scale)) return std::nullopt;
  return SlackReport{t, worst, chain_.link_midpoint(worst), T_worst, scale};
}

template <int dim>
EventAction StringModel<dim>::handle_events(double t, Eigen::VectorXd& y, const std::vector<int>& found) {
  CHAINSIM_VERIFY(module_ != nullptr, "events come from a module");
  unpack_state(t, y);
  refresh();
  Eigen::VectorXd ledgers = y.tail(1 + num_ledgers_);
  const EventAction action = module_->handle_events(*this, t, ledgers.tail(num_ledgers_), found);
  if (action.kind == EventAction::Kind::kTransfer) y = pack(ledgers);
  return action;
}

template <int dim>
void StringModel<dim>::add_link_responses(Points<dim>& target, const Eigen::VectorXd& nu) const {
  for_each_link([&](int j, int u, int) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    target.col(a) -= w_[a] * nu[u] * e_.col(j);
    target.col(b) += w_[b] * nu[u] * e_.col(j);
  });
  for (const Bend& bend : bends_) {
    const int u = link_unknown_[static_cast<std::size_t>(bend.link)];
    if (u >= 0) target.col(chain_.link_end(bend.link)) += w_[chain_.link_end(bend.link)] * nu[u] * (bend.e_plus - e_.col(bend.link));
  }
  if (contacts_.empty()) return;
  // A held node responds with w_i P: take back the normal part of its response (the links at it
  // are the only ones that moved it, so its response is its links' terms above).
  for (const NodeContact<dim>& c : contacts_) {
    const int i = c.node;
    const auto [jm, jp] = node_links(i);
    Vec<dim> response = Vec<dim>::Zero();
    if (jm >= 0 && link_unknown_[static_cast<std::size_t>(jm)] >= 0) response += nu[link_unknown_[static_cast<std::size_t>(jm)]] * end_direction_at_contact(jm);
    if (jp >= 0 && link_unknown_[static_cast<std::size_t>(jp)] >= 0) response -= nu[link_unknown_[static_cast<std::size_t>(jp)]] * e_.col(jp);
    target.col(i) -= w_[i] * c.normal.dot(response) * c.normal;
  }
}

template <int dim>
void StringModel<dim>::exclude_slack_links() {
  if (num_slack_ == 0) return;
  for_each_link([&](int j, int u, int) {
    if (link_slack(j)) system_->exclude(u);
  });
}

template <int dim>
const Eigen::VectorXd& StringModel<dim>::solve_tensions(double t) {
  if (!allows_slack()) return system_->solve(t);
  exclude_slack_links();
  // Round-off is not a release: a tension counts as negative below −slack_tolerance times the larger
  // of max |T| and the physical tension scale (as find_slack judges slack).
  const long releases = system_->complementarity_stats().calls_with_release;
  const Eigen::VectorXd& T = system_->solve_complementarity(t, [&](double max_abs) {
    return options_.slack_tolerance * std::max(max_abs, physical_scales().tension);
  });
  // The taut links this solve released: accept_step judges them (a release that the next evaluations take
  // back within one step is still a release). O(N), only on a solve that released a link.
  if (system_->complementarity_stats().calls_with_release != releases) {
    for_each_link([&](int j, int u, int) {
      if (!link_slack(j) && system_->excluded(u)) released_[static_cast<std::size_t>(j)] = 1;
    });
    any_released_ = true;
  }
  return T;
}

template <int dim>
void StringModel<dim>::set_slack(int j, bool slack) {
  if (!allows_slack()) throw InputError("a link can be declared slack only with solver.slack = \"allow\"");
  if (j < 0 || j >= chain_.num_links()) throw InputError(fmt::format("set_slack: no link {}", j));
  char& flag = slack_[static_cast<std::size_t>(j)];
  if ((flag != 0) != slack) num_slack_ += slack ? 1 : -1;
  flag = slack ? 1 : 0;
  slack_offset_[static_cast<std::size_t>(j)] = 0;
  if (!release_flight_.empty()) release_flight_[static_cast<std::size_t>(j)] = 0;
}

template <int dim>
double StringModel<dim>::release_root() const {
  double g = 1;
  if (!allows_slack() || !system_) return g;
  const Eigen::VectorXd& T = system_->solution();
  const double scale = std::max(T.size() ? T.cwiseAbs().maxCoeff() : 0.0, physical_scales().tension);
  if (!(scale > 0)) return g;
  for_each_link([&](int j, int u, int) {
    if (link_slack(j) || link_bent(j) || borders_front(j)) return;
    const double gj = system_->excluded(u) ? -options_.slack_tolerance : T[u] / scale + options_.slack_tolerance;
    g = std::min(g, gj);
  });
  return g;
}

template <int dim>
int StringModel<dim>::release_links() {
  if (!allows_slack() || !system_) return 0;
  const Eigen::VectorXd& T = system_->solution();
  const double scale = std::max(T.size() ? T.cwiseAbs().maxCoeff() : 0.0, physical_scales().tension);
  if (!(scale > 0)) return 0;
  std::vector<int> released;
  for_each_link([&](int j, int u, int) {
    if (link_slack(j) || link_bent(j) || borders_front(j)) return;
    if (system_->excluded(u) || T[u] / scale + options_.slack_tolerance <= 0) released.push_back(j);
  });
  for (const int j : released) {
    const double h = chain_.link_length(j);
    set_slack(j, true);
    slack_offset_[static_cast<std::size_t>(j)] = std::max(0.0, (current_length(j) - h) / h) + kSlackGap;
    release_flight_[static_cast<std::size_t>(j)] = 1;
    rebound_time_[static_cast<std::size_t>(j)] = NAN;
  }
  return static_cast<int>(released.size());
}

template <int dim>
bool StringModel<dim>::borders_front(int j) const {
  const int L = chain_.num_links();
  const auto held = [&](int i) {
    if (chain_.closed()) i = (i + L) % L;
    return i >= 0 && i < L && link_unknown_[static_cast<std::size_t>(i)] < 0;
  };
  return held(j - 1) || held(j + 1);
}

template <int dim>
double StringModel<dim>::slack_gap() const {
  double g = 1;
  if (num_slack_ == 0) return g;
  for (int j = 0; j < chain_.num_links(); ++j) {
    if (!slack_[static_cast<std::size_t>(j)]) continue;
    g = std::min(g, slack_root(j));
  }
  return g;
}

template <int dim>
double StringModel<dim>::slack_root(int j) const {
  // A link that separated at a snap starts with its root function at +kSlackGap, never at zero (link_impulses,
  // step 4: ARKODE deactivates a root function that is zero at a restart). The offset is needed only until the
  // link has started opening: from the top of its flight (l̇ ≥ 0) on it is dropped, so that the return is
  // located at the link's length itself, not kSlackGap of it past (which every rebound added to the taut
  // length: taut links up to 2.8e-6 h too long, W_links ~1e-8 J at every rtol; docs/model.md §9). The root
  // function then jumps down at the top but stays > 0 there (the link is shorter than its length): ARKODE
  // looks only for sign changes, at a step's ends and, in a step that has one, at the points its rootfinder
  // brackets it with, so a jump between positive values neither makes a root nor hides the return. A link
  // that never got shorter than its length (its excess at the separation, from the drift of the taut lengths,
  // deeper than its flight) drops to ≤ 0 at its top: the root is located there and snap() catches it at rest.
  // A flight cannot end before its top (the link shortens until then); one too shallow to resolve is held
  // taut at the snap (hold_unresolved_flights) and has no offset. A bent link's rate is not e·Δv: it keeps its
  // offset.
  const auto k = static_cast<std::size_t>(j);
  const double h = chain_.link_length(j);
  double offset = slack_offset_[k];
  if (offset > 0 && (bends_.empty() || bend_of(j) == nullptr)) {
    // A release flight (release_links) starts at rest at its length l_r, its rate a drift's: its offset
    // (l_r − h)⁺/h + kSlackGap drops to (l_r − h)⁺/h once an accepted step has found the link shorter than l_r
    // by kFlightDepth h (accept_step), so that its return is located at l_r (within the drift of h), not
    // kSlackGap past it, and not at its start; until then it keeps the whole offset.
    if (release_flight_[k] == 2) {
      offset -= kSlackGap;
    } else if (release_flight_[k] == 0) {
      const int a = chain_.link_start(j), b = chain_.link_end(j);
      if ((x_.col(b) - x_.col(a)).dot(v_.col(b) - v_.col(a)) >= 0) offset = 0;
    }
  }
  return (h - current_length(j)) / h + offset;
}

template <int dim>
void StringModel<dim>::accept_step(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (!allows_slack() || !system_) return;
  // A taut link shorter than (1 − kSlackGap) h is slack: the tension solve released it during the step
  // (a taut link's length is held to the integration tolerance, far below kSlackGap). A slack link past
  // its length is a snap the root function missed: refuse to go on with a string longer than its
  // material (the one root function would stay negative). O(N), no tension solve.
  unpack_state(t, y);
  for (int j = 0; j < chain_.num_links(); ++j) {
    if (link_unknown_[static_cast<std::size_t>(j)] < 0) continue;  // in no arc: a front holds it
    const double h = chain_.link_length(j);
    const double gap = (h - current_length(j)) / h;
    if (!link_slack(j)) {
      // (Released: no tension at the step's last evaluation. A link short only by the drift of the
      // constraints, which at loose tolerances is far above kSlackGap, keeps its tension: it is taut.)
      if (goes_slack(gap, kSlackGap, link_tension(j), any_released_ && released_[static_cast<std::size_t>(j)])) {
        set_slack(j, true);
        rebound_time_[static_cast<std::size_t>(j)] = NAN;  // released by the tensions: a flight, not a rebound
      }
    } else {
      // A release flight shorter than its length at the release by more than round-off (kFlightDepth): its return
      // is now a crossing of l_r (slack_root). Without the depth, links at rest at their length in free fall took
      // (l_r − l)/h = round-off as their root, and snapped at once by dozens, at rates of round-off that the
      // impulses turned into separations and back (a folded chain jerked down, 401 nodes).
      const auto k = static_cast<std::size_t>(j);
      if (release_flight_[k] == 1 && gap + slack_offset_[k] - kSlackGap > kFlightDepth) release_flight_[k] = 2;
      const double root = slack_root(j);
      if (!(root < -kSlackGap)) continue;
      // The snap's own root function (its offset dropped from the top of the flight on): a link past its top that
      // had gone 4e-7 h past its length passed unflagged when the check added the offset regardless.
      throw NumericalError(fmt::format("at t = {:.9g} s slack link {} (s = {:.6g} m) is {:.3g} of its length past it: "
                                       "its snap taut was not located",
                                       t, j, chain_.link_midpoint(j), -root),
                           t);
    }
  }
  if (any_released_) {
    std::fill(released_.begin(), released_.end(), 0);
    any_released_ = false;
  }
}

template <int dim>
typename StringModel<dim>::SnapResult StringModel<dim>::snap(double t, double speed_floor) {
  SnapResult result;
  links();
  const int L = chain_.num_links();
  // 1. The slack links at their length are caught: taut again.
  std::vector<int> caught;
  for (int j = 0; j < L; ++j)
    if (link_slack(j) && slack_root(j) <= kSnapWindow) {
      set_slack(j, false);
      ++result.caught;
      caught.push_back(j);
    }
  if (result.caught == 0) {
    // The root was located on ARKODE's interpolant; the state of the step recomputed to the event
    // differs from it by the integration error, so the link may be a little short of its length:
    // catch the nearest slack link if it is within kSnapWindow plus that error (kCatchWindow).
    int nearest = -1;
    double nearest_gap = INFINITY;
    for (int j = 0; j < L; ++j) {
      if (!link_slack(j)) continue;
      const double gap = slack_root(j);
      if (gap < nearest_gap) {
        nearest_gap = gap;
        nearest = j;
      }
    }
    if (nearest < 0 || !(nearest_gap < kCatchWindow)) return result;
    set_slack(nearest, false);
    ++result.caught;
    caught.push_back(nearest);
  }
  // 2. The accumulation rule (docs/model.md §9, "Accumulating rebounds"): a caught link whose rebounds would
  //    accumulate within the motion's time over a link takes e = 0. Only for 0 < e < 1 (e = 0 is inelastic
  //    already; e = 1 never accumulates).
  const double e = options_.snap_restitution;
  std::vector<char> inelastic;
  if (e > 0 && e < 1) {
    inelastic.assign(static_cast<std::size_t>(L), 0);
    for (int j : caught)
      if (rebounds_accumulate(j, t, e)) inelastic[static_cast<std::size_t>(j)] = 1;
  }
  const SnapResult impulses = link_impulses(t, e, speed_floor, inelastic.empty() ? nullptr : &inelastic, true);
  result.speed = impulses.speed;
  result.dissipated = impulses.dissipated;
  result.support_work = impulses.support_work;
  result.support_impulse = impulses.support_impulse;
  return result;
}

template <int dim>
bool StringModel<dim>::hold_unresolved_flights(double t, std::vector<int>& separating) {
  if (separating.empty()) return false;
  // The accelerations after the jump with the separating links out of the tension solve: each one's free
  // closing acceleration d²l/dt² = (Δx·Δa + |Δv|² − l̇²)/l. Its flight from its length at l̇ = −u under that
  // acceleration a > 0 reaches u²/(2a) below it: within kSlackGap h_j, the gap at which accept_step declares a
  // released link slack, it is not a flight the model resolves, and the link is held taut.
  for (const int j : separating) set_slack(j, true);
  evaluate_current(t);
  bool held = false;
  std::vector<int> flying;
  for (const int j : separating) {
    bool hold = false;
    if (bends_.empty() || bend_of(j) == nullptr) {  // a bent link's length runs over its point: it flies
      const int a = chain_.link_start(j), b = chain_.link_end(j);
      const Vec<dim> dx = x_.col(b) - x_.col(a), dv = v_.col(b) - v_.col(a), da = a_.col(b) - a_.col(a);
      const double l = dx.norm(), rate = dx.dot(dv) / l;
      const double closing = (dx.dot(da) + dv.squaredNorm() - rate * rate) / l;
      hold = closing > 0 && rate * rate < 2 * closing * kSlackGap * chain_.link_length(j);
    }
    if (hold) {
      set_slack(j, false);
      held = true;
    } else {
      flying.push_back(j);
    }
  }
  separating.swap(flying);
  return held;
}

template <int dim>
bool StringModel<dim>::rebounds_accumulate(int j, double t, double e) const {
  // Link j separated at its previous snap, at t_s with speed u_s, flew for τ = t − t_s and is back at
  // approach speed u. Its ends' closing acceleration over the flight is a = (u_s + u)/τ; held at that a, the
  // rebounds that e would give, e u, e² u, …, last 2 e u / ((1 − e) a) in all and end with the link taut,
  // having dissipated ½ μ u², what one perfectly inelastic snap dissipates now. The rule takes that snap when
  // the accumulation would end within kAccumulation of the time h_j / U the motion takes to cross the link.
  const std::size_t k = static_cast<std::size_t>(j);
  if (k >= rebound_time_.size() || std::isnan(rebound_time_[k])) return false;
  const double u = link_rate(j), tau = t - rebound_time_[k];
  if (!(u > 0) || !(tau > 0)) return false;
  const double a = (rebound_speed_[k] + u) / tau;
  const double accumulation = 2 * e * u / ((1 - e) * a);
  return accumulation < kAccumulation * chain_.link_length(j) / speed_scale();
}

template <int dim>
double StringModel<dim>::impact(double t, double e) {
  if (!allows_slack()) {
    return project(t);
  } else {
    // Unilateral links: the positions onto the constraints, the held nodes' normal velocity taken
    // (Moreau's law, restitution 0), and the links' impulses the snap's complementarity problem at
    // e = 0 on the same contact-reduced matrix: a link that the landing would push goes slack.
    project_positions(t);
    // A link separates (goes slack) faster than kSeparation of the landing's speed, not of the links'
    // approach speed alone: that is round-off at a tangential touchdown.
    double speed = 0;
    for (const NodeContact<dim>& c : contacts_) {
      speed = std::max(speed, v_.col(c.node).norm());
      v_.col(c.node) -= c.normal.dot(v_.col(c.node)) * c.normal;
    }
    return link_impulses(t, e, speed).support_work;
  }
}

template <int dim>
typename StringModel<dim>::SnapResult StringModel<dim>::link_impulses(double t, double e, double u_floor,
                                                                      const std::vector<char>* inelastic,
                                                                      bool rebounds) {
  SnapResult result;
  const int L = chain_.num_links();
  links();
  // 2. The impulse problem on the taut links: w = −(1 + e) u⁻ − A P ≥ 0, P ≥ 0, P w = 0 (the
  //    tension matrix A: a link's rate of lengthening changes by (A P)_j; with held nodes, the
  //    contact-reduced one, their responses w_i P_i).
  const Points<dim> v_before = v_;
  Eigen::VectorXd u_before = Eigen::VectorXd::Zero(L);
  double u_scale = u_floor;
  system_->zero();
  assemble_matrix();
  for_each_link([&](int j, int u, int) {
    u_before[j] = link_rate(j);
    // Newton's restitution acts on an approach (u⁻ > 0); a link already shortening (a released one not
    // yet slack, or one shortening at the start) is held only from lengthening: u⁺ ≤ 0.
    const double e_j = inelastic && (*inelastic)[static_cast<std::size_t>(j)] ? 0.0 : e;
    system_->rhs(u) = -u_before[j] - e_j * std::max(u_before[j], 0.0);
    if (!link_slack(j)) u_scale = std::max(u_scale, std::abs(u_before[j]));
  });
  exclude_slack_links();
  const Eigen::VectorXd P = system_->solve_complementarity(
      t, [&](double max_abs) { return options_.slack_tolerance * max_abs; });
  // 3. The velocities jump; the supports take the impulses at prescribed nodes, the obstacles the
  //    normal part of the links' impulses at held nodes (m Δv − the links' impulse; no work: n·v = 0
  //    before and after).
  add_link_responses(v_, -P);
  Points<dim> link_impulse = Points<dim>::Zero(dim, chain_.num_nodes());
  for_each_link([&](int j, int u, int) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    const Vec<dim> J = P[u] * e_.col(j);  // on node a; −J on node b (−P e⁺ for a link bent over a point)
    const Bend* bend = bends_.empty() ? nullptr : bend_of(j);
    const Vec<dim> Jb = bend ? Vec<dim>(P[u] * bend->e_plus) : J;
    // The point a link is bent over takes P (e⁻ − e⁺) from the string's side: an external impulse (no work,
    // the point is fixed), as its force T (e⁻ − e⁺) is an external force (bend_reaction).
    if (bend) result.support_impulse += J - Jb;
    link_impulse.col(a) += J;
    link_impulse.col(b) -= Jb;
    if (path_of_[a] >= 0) result.support_impulse -= J;
    if (path_of_[b] >= 0) result.support_impulse += Jb;
  });
  result.support_work = supports_work(-P);
  for (const NodeContact<dim>& c : contacts_)
    result.support_impulse += m_[c.node] * (v_.col(c.node) - v_before.col(c.node)) - link_impulse.col(c.node);
  // 4. The energy dissipated, Σ P_j (u⁻_j + u⁺_j)/2, and the links that separate go slack.
  links();
  std::vector<int> separating;
  for_each_link([&](int j, int u, int) {
    const double u_after = link_rate(j);
    result.dissipated += 0.5 * P[u] * (u_before[j] + u_after);
    if (!link_slack(j) && u_after < -kSeparation * u_scale) separating.push_back(j);
  });
  result.speed = u_scale;
  // 4a. At a snap, a separation whose flight would not open the link beyond kSlackGap of its length is held
  //     taut (hold_unresolved_flights): the velocities are then projected onto the taut links' lengths below.
  const bool held = rebounds && hold_unresolved_flights(t, separating);
  for (const int j : separating) {
    const double u_after = link_rate(j);
    set_slack(j, true);
    // Its root function starts at +kSlackGap, never at zero: ARKODE deactivates a root function that
    // is zero at a restart, and would miss the link's return to its length if it came at once. The offset
    // lasts until the top of its flight (slack_root).
    slack_offset_[static_cast<std::size_t>(j)] =
        std::max(0.0, (l_[j] - chain_.link_length(j)) / chain_.link_length(j)) + kSlackGap;
    // A rebound of snap() is recorded for the accumulation rule; a link that separates at the start or
    // at a landing begins a flight, not a rebound.
    if (static_cast<std::size_t>(j) < rebound_time_.size()) {
      rebound_time_[static_cast<std::size_t>(j)] = rebounds ? t : NAN;
      rebound_speed_[static_cast<std::size_t>(j)] = -u_after;
    }
  }
  // 5. The module's constraints (an inserted kink's arms meeting, §2.5): the links' impulses alone leave their
  //    rates Ċ ≠ 0, which the drift control then took out over the following steps with work no ledger booked (a
  //    coil with an inserted kink whose tip link snapped: energy residual 3.2e-6, the same at every rtol; review of
  //    #27). Their impulses are part of every impulse problem (a snap, a landing, the start): the mass-weighted
  //    projection onto Ċ = 0 with the links that stay taut held at zero rate (a bilateral projection; the links that
  //    separated above are slack by now and free, so a separation is kept, and their rebound speed is read again).
  //    Its change of kinetic energy less the driven supports' work in it is booked with the links' dissipation,
  //    that work with the supports' (review of #27: it was all in W_snap, which a driven end could make positive),
  //    and the momentum it gives the string is the supports' impulse (the constraints' own impulses sum to zero).
  if (module_) {
    constraints_.clear();
    module_->node_constraints(*this, constraints_);
  }
  if (held || (module_ && !constraints_.empty())) {
    const double before = kinetic_energy();
    const Vec<dim> p_before = momentum();
    const double work = project_velocities(t);
    result.dissipated += before + work - kinetic_energy();
    result.support_work += work;
    result.support_impulse += momentum() - p_before;
    links();
    for (std::size_t j = 0; j < rebound_time_.size(); ++j)
      if (link_slack(static_cast<int>(j)) && rebound_time_[j] == t) rebound_speed_[j] = -link_rate(static_cast<int>(j));
  }
  return result;
}

template class StringModel<2>;
template class StringModel<3>;

}  // namespace chainsim
