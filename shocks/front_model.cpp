// A string with fronts (heaps and folds): see front_model.hpp.
#include "front_model.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "shocks/jump_conditions.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

namespace {
/// A heap takes in an arc's end node when its partial link shrinks to kRemove·h and gives out a new
/// node when it grows to kInsert·h: the partial link stays in [h/2, 3h/2], away from zero length
/// (where its direction is undefined).
constexpr double kRemove = 0.5, kInsert = 1.5;
/// The last node of an arc cannot be taken in; the run stops when its partial link is this short.
constexpr double kLastPartial = 1e-3;
/// A string meeting a plane at less than this cosine between its tangent and the plane's normal
/// runs along the plane: the contact point is then ill-defined and the run stops.
constexpr double kGrazing = 1e-3;
constexpr double kProjectionTolerance = 1e-13;
constexpr int kProjectionIterations = 30;

template <int dim>
Vec<dim> unit(const Vec<dim>& d, const char* what) {
  const double n = d.norm();
  if (!(n > 0) || !std::isfinite(n)) throw RecoverableError(fmt::format("{} has zero length", what));
  return d / n;
}
}  // namespace

template <int dim>
FrontModel<dim>::FrontModel(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                            std::vector<PrescribedNode<dim>> prescribed, std::vector<HeapSpec<dim>> heaps,
                            std::optional<FoldSpec> fold, const FrontModelOptions& options)
    : chain_(std::move(chain)), forces_(std::move(forces)), prescribed_(std::move(prescribed)), options_(options) {
  require_in_range("stabilization_time", options_.stabilization_time, 0.0, INFINITY);
  if (chain_.closed()) throw InputError("fronts are tracked on open strings only");
  const int L = chain_.num_links();
  h_ = chain_.link_length(0);
  for (int j = 1; j < L; ++j)
    if (std::abs(chain_.link_length(j) - h_) > 1e-12 * h_)
      throw InputError("a string with fronts needs links of equal material length");
  if (L < 2) throw InputError(fmt::format("a string with fronts needs at least 2 links, got {}", L));
  lambda_ = chain_.density();
  n_ = chain_.num_nodes();
  const double ell = chain_.length();
  // 1. Prescribed nodes.
  path_of_.assign(static_cast<std::size_t>(n_), -1);
  for (std::size_t k = 0; k < prescribed_.size(); ++k) {
    const int node = prescribed_[k].node;
    if (node < 0 || node >= n_)
      throw InputError(fmt::format("prescribed node {} does not exist: the string has nodes 0..{}", node, n_ - 1));
    if (path_of_[node] >= 0) throw InputError(fmt::format("node {} has two prescribed motions", node));
    path_of_[node] = static_cast<int>(k);
  }
  // 2. Fronts in order of s: heap before, fold, heap after.
  const HeapSpec<dim>* before = nullptr;
  const HeapSpec<dim>* after = nullptr;
  for (auto& heap : heaps) {
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
  if (fold) {
    require_in_range("fold.dissipation", fold->dissipation, 0.0, 1.0);
    require_in_range("fold.s0", fold->s0, 0.0, ell, Bound::kClosed, Bound::kOpen);
    if ((before && fold->s0 <= before->s0) || (after && fold->s0 >= after->s0))
      throw InputError("the fold must lie between the heaps");
  }
  if (before && after && after->s0 - before->s0 < 2 * h_)
    throw InputError("the heaps are less than two links apart: use more nodes");
  // 3. Arcs: node ranges between the fronts.
  auto node_at_or_before = [&](double s) { return std::clamp(static_cast<int>(std::floor(s / h_ + 1e-9)), 0, n_ - 1); };
  int first = 0, last = n_ - 1;
  if (before) first = std::min(n_ - 1, static_cast<int>(std::ceil((before->s0 + kRemove * h_) / h_ - 1e-9)));
  if (after) last = std::max(first, static_cast<int>(std::floor((after->s0 - kRemove * h_) / h_ + 1e-9)));
  if (fold) {
    const int a = node_at_or_before(fold->s0);
    if (a < first || a + 1 > last) throw InputError("the fold must lie inside the moving part of the string");
    arcs_.push_back({first, a});
    arcs_.push_back({a + 1, last});
  } else {
    arcs_.push_back({first, last});
  }
  const int last_arc = static_cast<int>(arcs_.size()) - 1;
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
      const ArcRange& arc = arcs_[static_cast<std::size_t>(arc_minus >= 0 ? arc_minus : arc_plus)];
      if (arc.num_links() < 1)
        throw InputError("a heap on a plane needs at least one full link next to it (its direction is the string's)");
    }
    return front;
  };
  if (before) fronts_.push_back(heap_front(*before, -1, 0));
  if (fold) {
    Front front;
    front.kind = FrontKind::kFold;
    front.dissipation = fold->dissipation;
    front.arc_minus = 0;
    front.arc_plus = 1;
    fronts_.push_back(front);
  }
  if (after) fronts_.push_back(heap_front(*after, last_arc, -1));
  for (std::size_t k = 0; k < prescribed_.size(); ++k) {
    const int node = prescribed_[k].node;
    if (node < first || node > last)
      throw InputError(fmt::format("prescribed node {} lies inside a heap", node));
  }
  if (options_.stabilization_time > 0) alpha_ = beta_ = 1.0 / options_.stabilization_time;
  for (const auto& stop : options_.stop_at)
    if (stop.front < 0 || stop.front >= static_cast<int>(fronts_.size()))
      throw InputError(fmt::format("stop condition on front {}: the string has {} fronts", stop.front, fronts_.size()));
  // 4. Workspace, then check that the fronts sit where the specs say.
  for (Points<dim>* p : {&x_, &v_, &a_, &force_, &force_nc_, &front_force_, &tension_force_, &b_, &e_, &reaction_}) *p = Points<dim>::Zero(dim, n_);
  m_ = Eigen::VectorXd::Zero(n_);
  rebuild();
  x_ = chain_.positions();
  v_ = chain_.velocities();
  for (const auto& p : prescribed_) x_.col(p.node) = p.path->position(0.0);
  for (const Front& front : fronts_) {
    if (!front.on_plane) continue;
    const int inner = heap_end(front).inner;
    const double height = front.normal.dot(x_.col(inner) - front.point);
    if (height < 0)  // on the plane itself: the grazing check below says more
      throw InputError(fmt::format("the normal of the heap's plane must point to the string's side: node {} is "
                                   "{:.6g} m from the plane along it",
                                   inner, height));
  }
  try {
    front_states();
  } catch (const RecoverableError& e) {
    throw InputError(fmt::format("the initial shape does not fit the fronts: {}", e.what()));
  }
  std::vector<double> expected;
  if (before) expected.push_back(before->s0);
  if (fold) expected.push_back(fold->s0);
  if (after) expected.push_back(after->s0);
  // A front is where the links put it: a partial link is straight, so on a curved shape the front
  // lies off s0 by O(κ h²). That is accepted up to a tenth of a link; the masses follow the geometry.
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (std::abs(fs_[k].s0 - expected[k]) > std::max(1e-6 * ell, 0.1 * h_))
      throw InputError(fmt::format(
          "the {} front is meant to be at s0 = {:.9g} m but the initial shape puts it at s0 = {:.9g} m: "
          "place the {} at the string's material point s0",
          fronts_[k].kind == FrontKind::kHeap ? "heap" : "fold", expected[k], fs_[k].s0,
          fronts_[k].kind == FrontKind::kHeap ? "heap point" : "fold"));
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kFold && fs_[k].opening > kMaxFoldOpeningDeg * kPi / 180)
      throw InputError(fold_opened_message(k));
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kHeap) heap_moment0_ += heap_mass(k) * fs_[k].position;
}

template <int dim>
void FrontModel<dim>::rebuild() {
  arc_of_.assign(static_cast<std::size_t>(n_), -1);
  for (std::size_t k = 0; k < arcs_.size(); ++k)
    for (int i = arcs_[k].first; i <= arcs_[k].last; ++i) arc_of_[i] = static_cast<int>(k);
  slot_.assign(static_cast<std::size_t>(n_), -1);
  num_moving_ = 0;
  for (int i = 0; i < n_; ++i)
    if (in_arc(i) && path_of_[i] < 0) slot_[i] = num_moving_++;
  std::vector<int> links;
  std::vector<bool> closed;
  first_unknown_.assign(arcs_.size(), -1);
  int unknown = 0;
  for (std::size_t k = 0; k < arcs_.size(); ++k) {
    if (arcs_[k].num_links() == 0) continue;
    first_unknown_[k] = unknown;
    unknown += arcs_[k].num_links();
    links.push_back(arcs_[k].num_links());
    closed.push_back(false);
  }
  system_ = links.empty() ? nullptr : std::make_unique<TensionSystem>(links, closed, std::vector<Junction*>{}, "tridiagonal");
  fs_.assign(fronts_.size(), FrontState{});
}

template <int dim>
typename FrontModel<dim>::HeapEnd FrontModel<dim>::heap_end(const Front& front) const {
  HeapEnd end;
  end.after = front.arc_plus < 0;
  end.arc = end.after ? front.arc_minus : front.arc_plus;
  const ArcRange& arc = arcs_[static_cast<std::size_t>(end.arc)];
  end.node = end.after ? arc.last : arc.first;
  end.inner = end.after ? end.node - 1 : end.node + 1;
  end.outer = end.after ? end.node + 1 : end.node - 1;
  end.removable = arc.last > arc.first && path_of_[end.node] < 0;
  // A node comes out whole only if the front then stays inside the string (s0 = s_outer ± h/2).
  end.insertable = end.after ? end.outer <= n_ - 2 : end.outer >= 1;
  return end;
}

template <int dim>
std::string FrontModel<dim>::fold_opened_message(std::size_t front) const {
  return fmt::format(
      "the fold at s0 = {:.6g} m has opened: its arms leave it {:.3g} degrees from antiparallel (a tight bight allows "
      "at most {:g}; a dissipative fold needs both arms along one line, and a bight that opens, as in a folded chain "
      "whose ends are apart, is resolved by the string solver without [effects.fold]: docs/shocks.md)",
      fs_[front].s0, fs_[front].opening * 180 / kPi, kMaxFoldOpeningDeg);
}

template <int dim>
Vec<dim> FrontModel<dim>::gravity() const {
  for (const auto& force : forces_)
    if (const auto* g = dynamic_cast<const Gravity<dim>*>(force.get())) return g->g();
  return Vec<dim>::Zero();
}

template <int dim>
void FrontModel<dim>::unpack(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  const int voff = dim * num_moving_;
  for (int i = 0; i < n_; ++i) {
    if (!in_arc(i)) continue;
    const int k = slot_[i];
    if (k >= 0) {
      x_.col(i) = y.template segment<dim>(dim * k);
      v_.col(i) = y.template segment<dim>(voff + dim * k);
    } else {
      const EndPath<dim>& path = *prescribed_[static_cast<std::size_t>(path_of_[i])].path;
      x_.col(i) = path.position(t);
      v_.col(i) = path.velocity(t);
    }
  }
}

template <int dim>
void FrontModel<dim>::front_states() {
  m_.setZero();
  front_force_.setZero();
  for (const ArcRange& arc : arcs_)
    for (int j = arc.first; j < arc.last; ++j) {
      m_[j] += 0.5 * lambda_ * h_;
      m_[j + 1] += 0.5 * lambda_ * h_;
    }
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    const Front& front = fronts_[k];
    FrontState& s = fs_[k];
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(front);
      const bool after = end.after;
      const int node = end.node;
      // The partial link: its length l, direction e (from the arc into the heap), the contact point
      // and w = dl/dt, the rate at which the arc gains material (w < 0: it runs into the heap).
      double l = 0, w = 0;
      // On a plane the partial link continues the arc's last full link; once a crossing has left the
      // arc without one, it keeps that link's last direction (stored below at every evaluation).
      const bool has_link = arcs_[static_cast<std::size_t>(end.arc)].num_links() > 0;
      if (!front.on_plane) {  // pinned at the point: e and l from the end node to it
        const Vec<dim> d = front.point - x_.col(node);
        l = d.norm();
        if (!(l > 1e-9 * h_)) throw RecoverableError(fmt::format("the partial link at the heap has collapsed (node {})", node));
        s.direction = d / l;
        s.position = front.point;
        w = -v_.col(node).dot(s.direction);
      } else {  // on a plane: the arc's last link continued to where it meets the plane
        const Vec<dim> link = has_link ? Vec<dim>(x_.col(node) - x_.col(end.inner)) : front.last_direction;
        const Vec<dim> dv = has_link ? Vec<dim>(v_.col(node) - v_.col(end.inner)) : Vec<dim>::Zero();
        const Vec<dim>& n = front.normal;
        const Vec<dim> e = unit<dim>(link, "the link next to the heap");
        const double ne = n.dot(e);
        if (!(ne < -kGrazing))
          throw RecoverableError(fmt::format("the string meets the heap's plane at a grazing angle (n·t = {:.3g} at node {})", ne, node));
        l = n.dot(front.point - x_.col(node)) / ne;
        if (!(l > 1e-9 * h_)) throw RecoverableError(fmt::format("node {} has gone through the heap's plane", node));
        const Vec<dim> e_dot = (dv - e * e.dot(dv)) / link.norm();
        s.direction = e;
        s.position = x_.col(node) + l * e;
        w = -(n.dot(v_.col(node)) + l * n.dot(e_dot)) / ne;
        if (has_link) fronts_[k].last_direction = e;  // kept for when a crossing empties the arc
        for (const ArcRange& arc : arcs_)
          for (int i = arc.first; i <= arc.last; ++i)
            if (n.dot(x_.col(i) - front.point) < 0)
              throw RecoverableError(fmt::format("node {} has gone through the heap's plane away from the contact", i));
      }
      const Vec<dim> e = s.direction;
      const Vec<dim> v_end = v_.col(node);
      s.inflow = w;
      const double tau = lambda_ * w * w * (1 + front.dissipation * jump::sign(w));
      const double sk = chain_.node_coordinate(node);
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
      m_[node] += lambda_ * l;
      front_force_.col(node) += tau * e;
    } else {
      const ArcRange& A = arcs_[front.arc_minus];
      const ArcRange& B = arcs_[front.arc_plus];
      const int a = A.last, b = B.first;
      // The fold direction e: the bisector of arc A's end link t_A and arc B's first link reversed
      // (−t_B), or the one of them that exists; with its rate ė, for the mass flux below.
      auto tangent = [&](int i, int j, const char* what, Vec<dim>& rate) -> Vec<dim> {  // of link i → j
        const Vec<dim> link = x_.col(j) - x_.col(i), link_rate = v_.col(j) - v_.col(i);
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
      const double c = (x_.col(b) - x_.col(a)).dot(e);
      const double lA = 0.5 * (h_ + c), lB = 0.5 * (h_ - c);
      const double sd = 0.5 * (v_.col(b) - v_.col(a)).dot(e);
      const double sg = jump::sign(sd);
      s.direction = e;
      s.position = 0.5 * (x_.col(a) + x_.col(b)) + 0.5 * h_ * e;
      s.s0 = chain_.node_coordinate(a) + lA;
      s.s0_dot = sd;
      s.l_minus = lA;
      s.l_plus = lB;
      s.tension_minus = lambda_ * sd * sd * (1 + front.dissipation * sg);
      s.tension_plus = lambda_ * sd * sd * (1 - front.dissipation * sg);
      s.power_shock = -2 * front.dissipation * lambda_ * std::abs(sd) * sd * sd;
      s.power_heap = 0;
      s.reaction.setZero();
      s.inflow = 0;
      m_[a] += lambda_ * lA;
      m_[b] += lambda_ * lB;
      // Material crosses from b to a at the rate l̇_A = ½ (u·e + (x_b − x_a)·ė), u = v_b − v_a, carrying
      // the momentum flux λ l̇_A u. For arms on one line (u = 2 ṡ0 e, ė = 0) that is 2 λ ṡ0² e = τ⁻ + τ⁺,
      // the paper's fold. Otherwise the remainder δ, shared equally by the two nodes, keeps momentum
      // exact, and the energy then balances with W_s = −2 f λ |ṡ0|³ exactly (docs/shocks.md).
      const Vec<dim> u = v_.col(b) - v_.col(a);
      const double lA_rate = 0.5 * (u.dot(e) + (x_.col(b) - x_.col(a)).dot(e_rate));
      const Vec<dim> delta = lambda_ * lA_rate * u - 2 * lambda_ * sd * sd * e;
      front_force_.col(a) += s.tension_minus * e + 0.5 * delta;
      front_force_.col(b) += s.tension_plus * e + 0.5 * delta;
    }
  }
  for (int i = 0; i < n_; ++i)
    if (slot_[i] >= 0 && !(m_[i] > 1e-12 * lambda_ * h_))
      throw RecoverableError(fmt::format("node {} has lost its mass (a front overshot it)", i));
}

template <int dim>
double FrontModel<dim>::evaluate(double t) {
  const NodeState<dim> state{t, x_, v_, m_};
  force_.setZero();
  force_nc_.setZero();
  for (const auto& force : forces_) force->add_force(state, force->conservative() ? force_ : force_nc_);
  for (int i = 0; i < n_; ++i) {
    if (!in_arc(i)) continue;
    if (path_of_[i] < 0)
      b_.col(i) = (force_.col(i) + force_nc_.col(i) + front_force_.col(i)) / m_[i];
    else
      b_.col(i) = prescribed_[static_cast<std::size_t>(path_of_[i])].path->acceleration(t);
  }
  auto w = [&](int i) { return path_of_[i] < 0 ? 1.0 / m_[i] : 0.0; };
  Points<dim>& tension_force = tension_force_;
  tension_force.setZero();
  if (system_) {
    system_->zero();
    const double beta2 = beta_ * beta_;
    for (std::size_t k = 0; k < arcs_.size(); ++k) {
      const ArcRange& arc = arcs_[k];
      if (arc.num_links() == 0) continue;
      const int u0 = first_unknown_[k];
      Vec<dim> e_prev = Vec<dim>::Zero();
      for (int j = arc.first; j < arc.last; ++j) {
        const int u = u0 + (j - arc.first);
        const Vec<dim> dx = x_.col(j + 1) - x_.col(j), dv = v_.col(j + 1) - v_.col(j);
        const double l = dx.norm();
        if (!(l > 1e-6 * h_) || !std::isfinite(l))
          throw RecoverableError(fmt::format("link {} has collapsed to length {:g}", j, l));
        const Vec<dim> e = dx / l;
        e_.col(j) = e;
        system_->add_diagonal(u, -(w(j) + w(j + 1)));
        if (j > arc.first) system_->set_coupling(u - 1, w(j) * e_prev.dot(e));
        const double stab = 2 * alpha_ * dx.dot(dv) + beta2 * 0.5 * (l * l - h_ * h_);
        system_->rhs(u) = -dv.squaredNorm() / l - e.dot(b_.col(j + 1) - b_.col(j)) - stab / l;
        e_prev = e;
      }
    }
    const Eigen::VectorXd& T = system_->solve(t);
    ++solves_;
    for (std::size_t k = 0; k < arcs_.size(); ++k) {
      const ArcRange& arc = arcs_[k];
      for (int j = arc.first; j < arc.last; ++j) {
        const double Tj = T[first_unknown_[k] + (j - arc.first)];
        tension_force.col(j) += Tj * e_.col(j);
        tension_force.col(j + 1) -= Tj * e_.col(j);
      }
    }
  }
  double power = 0;
  reaction_.setZero();
  for (int i = 0; i < n_; ++i) {
    if (!in_arc(i)) continue;
    if (path_of_[i] < 0) {
      a_.col(i) = b_.col(i) + tension_force.col(i) / m_[i];
      power += force_nc_.col(i).dot(v_.col(i));
    } else {
      a_.col(i) = b_.col(i);
      // the support's reaction R_i = m a − F − T − front force (drag on it counted as applied work too)
      reaction_.col(i) = m_[i] * a_.col(i) - force_.col(i) - force_nc_.col(i) - tension_force.col(i) -
                         front_force_.col(i);
      power += (reaction_.col(i) + force_nc_.col(i)).dot(v_.col(i));
    }
  }
  return power;
}

template <int dim>
void FrontModel<dim>::rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
  unpack(t, y);
  front_states();
  const double power = evaluate(t);
  const int voff = dim * num_moving_;
  Vec<dim> external = Vec<dim>::Zero();
  for (int i = 0; i < n_; ++i) {
    if (!in_arc(i)) continue;
    const int k = slot_[i];
    external += force_.col(i) + force_nc_.col(i) + reaction_.col(i);
    if (k < 0) continue;
    ydot.template segment<dim>(dim * k) = v_.col(i);
    ydot.template segment<dim>(voff + dim * k) = a_.col(i);
  }
  double w_shocks = 0, w_heaps = 0;
  Vec<dim> heap_moment_rate = Vec<dim>::Zero();
  for (std::size_t k = 0; k < fs_.size(); ++k) {
    const FrontState& s = fs_[k];
    w_shocks += s.power_shock;
    w_heaps += s.power_heap;
    external += s.reaction;
    if (fronts_[k].kind == FrontKind::kHeap) heap_moment_rate -= lambda_ * s.inflow * s.position;
  }
  const int base = 2 * dim * num_moving_;
  ydot[base] = power;
  ydot[base + 1] = w_shocks;
  ydot[base + 2] = w_heaps;
  ydot.template segment<dim>(base + kLedger) = external;
  ydot.template segment<dim>(base + kLedger + dim) = heap_moment_rate;
}

template <int dim>
void FrontModel<dim>::events(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g) {
  unpack(t, y);
  front_states();
  const double ell = chain_.length();
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    const Front& front = fronts_[k];
    const FrontState& s = fs_[k];
    double* gk = g.data() + 2 * k;
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(front);
      const double l = end.after ? s.l_minus : s.l_plus;
      gk[0] = l - (end.removable ? kRemove : kLastPartial) * h_;
      // When no node can come out any more, the event is the heap running empty.
      gk[1] = end.insertable ? l - kInsert * h_ : -(end.after ? ell - s.s0 : s.s0);
    } else {
      gk[0] = s.l_plus;   // the fold reaches arc B's first node
      gk[1] = s.l_minus;  // the fold reaches arc A's last node
    }
  }
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k) {
    const auto& stop = options_.stop_at[k];
    g[2 * static_cast<int>(fronts_.size()) + static_cast<int>(k)] = fs_[stop.front].s0 - stop.s;
  }
  // Each fold: positive while its arms are within kMaxFoldOpeningDeg of antiparallel.
  int q = 2 * static_cast<int>(fronts_.size()) + static_cast<int>(options_.stop_at.size());
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k].kind == FrontKind::kFold) g[q++] = std::cos(fs_[k].opening) - std::cos(kMaxFoldOpeningDeg * kPi / 180);
}

template <int dim>
std::vector<int> FrontModel<dim>::event_directions() const {
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
Eigen::VectorXd FrontModel<dim>::state_scale() const {
  const double ell = chain_.length();
  double v2 = gravity().norm() * ell;
  for (int i = 0; i < n_; ++i) v2 = std::max(v2, chain_.velocities().col(i).squaredNorm());
  const double speed = v2 > 0 ? std::sqrt(v2) : ell;
  const double mass = lambda_ * ell;
  Eigen::VectorXd scale(size());
  const int voff = dim * num_moving_;
  scale.head(voff).setConstant(ell);
  scale.segment(voff, voff).setConstant(speed);
  scale.segment(2 * voff, kLedger).setConstant(mass * speed * speed);
  scale.segment(2 * voff + kLedger, dim).setConstant(mass * speed);
  scale.tail(dim).setConstant(mass * ell);
  return scale;
}

template <int dim>
Eigen::VectorXd FrontModel<dim>::pack(const Eigen::VectorXd& ledger) const {
  Eigen::VectorXd y(size());
  const int voff = dim * num_moving_;
  for (int i = 0; i < n_; ++i) {
    const int k = slot_[i];
    if (k < 0) continue;
    y.template segment<dim>(dim * k) = x_.col(i);
    y.template segment<dim>(voff + dim * k) = v_.col(i);
  }
  y.tail(kLedger + 2 * dim) = ledger;
  return y;
}

template <int dim>
Eigen::VectorXd FrontModel<dim>::state_from_chain() const {
  Eigen::VectorXd ledger = Eigen::VectorXd::Zero(kLedger + 2 * dim);
  return pack(ledger);
}

template <int dim>
void FrontModel<dim>::project(double t) {
  // Smallest mass-weighted correction onto |Δx_j| = h (Newton), then onto e_j·Δv_j = 0, arc by arc,
  // through the tension matrix −G W Gᵀ (as StringModel::make_consistent).
  if (!system_) return;
  for (const auto& p : prescribed_) {
    x_.col(p.node) = p.path->position(t);
    v_.col(p.node) = p.path->velocity(t);
  }
  auto w = [&](int i) { return path_of_[i] < 0 ? 1.0 / m_[i] : 0.0; };
  auto assemble = [&](bool velocity) {
    system_->zero();
    double worst = 0;
    for (std::size_t k = 0; k < arcs_.size(); ++k) {
      const ArcRange& arc = arcs_[k];
      Vec<dim> e_prev = Vec<dim>::Zero();
      for (int j = arc.first; j < arc.last; ++j) {
        const int u = first_unknown_[k] + (j - arc.first);
        const Vec<dim> dx = x_.col(j + 1) - x_.col(j);
        const double l = dx.norm();
        const Vec<dim> e = dx / l;
        e_.col(j) = e;
        system_->add_diagonal(u, -(w(j) + w(j + 1)));
        if (j > arc.first) system_->set_coupling(u - 1, w(j) * e_prev.dot(e));
        system_->rhs(u) = velocity ? e.dot(v_.col(j + 1) - v_.col(j)) : l - h_;
        worst = std::max(worst, std::abs(system_->rhs(u)) / (velocity ? 1.0 : h_));
        e_prev = e;
      }
    }
    return worst;
  };
  auto correct = [&](Points<dim>& target, const Eigen::VectorXd& nu) {
    for (std::size_t k = 0; k < arcs_.size(); ++k) {
      const ArcRange& arc = arcs_[k];
      for (int j = arc.first; j < arc.last; ++j) {
        const double n = nu[first_unknown_[k] + (j - arc.first)];
        target.col(j) -= w(j) * n * e_.col(j);
        target.col(j + 1) += w(j + 1) * n * e_.col(j);
      }
    }
  };
  for (int it = 0;; ++it) {
    const double worst = assemble(false);
    if (worst <= kProjectionTolerance) break;
    if (it == kProjectionIterations)
      throw NumericalError(fmt::format("after a front crossing at t = {:.9g} s the links cannot be projected back "
                                       "to their lengths (still off by {:.3g} of h)",
                                       t, worst),
                           t);
    correct(x_, system_->solve(t));
  }
  assemble(true);
  correct(v_, system_->solve(t));
}

template <int dim>
double FrontModel<dim>::make_consistent(double t0) {
  const Points<dim> before = x_;
  front_states();
  project(t0);
  double moved = 0;
  for (int i = 0; i < n_; ++i)
    if (in_arc(i)) moved = std::max(moved, (x_.col(i) - before.col(i)).norm());
  chain_.positions() = x_;
  chain_.velocities() = v_;
  return moved;
}

template <int dim>
typename FrontModel<dim>::EventAction FrontModel<dim>::handle_events(double t, Eigen::VectorXd& y,
                                                                     const std::vector<int>& found) {
  unpack(t, y);
  front_states();
  const int nf = static_cast<int>(fronts_.size());
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k)
    if (found[static_cast<std::size_t>(2 * nf) + k] != 0)
      return {EventAction::Kind::kStop,
              fmt::format("front {} reached s0 = {:.9g} m", options_.stop_at[k].front, options_.stop_at[k].s)};
  for (std::size_t k = 0, q = static_cast<std::size_t>(2 * nf) + options_.stop_at.size(); k < fronts_.size(); ++k) {
    if (fronts_[k].kind != FrontKind::kFold) continue;
    if (found[q++] != 0) return {EventAction::Kind::kStop, fold_opened_message(k)};
  }
  // Kinetic energy and momentum before, to book what the crossing changes.
  auto kinetic = [&]() {
    double K = 0;
    for (int i = 0; i < n_; ++i)
      if (in_arc(i)) K += 0.5 * m_[i] * v_.col(i).squaredNorm();
    return K;
  };
  Eigen::VectorXd ledger = y.tail(kLedger + 2 * dim);
  auto impulse = [&]() { return ledger.template segment<dim>(kLedger); };
  auto heap_moment = [&]() { return ledger.template segment<dim>(kLedger + dim); };
  const double E_before = kinetic() + potential(ledger);
  for (int f = 0; f < nf; ++f) {
    const int e0 = found[static_cast<std::size_t>(2 * f)], e1 = found[static_cast<std::size_t>(2 * f + 1)];
    if (e0 == 0 && e1 == 0) continue;
    Front& front = fronts_[f];
    const FrontState s = fs_[f];
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(front);
      const bool after = end.after;
      ArcRange& arc = arcs_[static_cast<std::size_t>(end.arc)];
      const int node = end.node, inner = end.inner, outer = end.outer;
      if (e0 != 0) {
        if (!end.removable)
          return {EventAction::Kind::kStop,
                  fmt::format("the string has run into the heap: its last node is {:.3g} h from the heap point",
                              kLastPartial)};
        // The end node joins its neighbour: one parcel, momentum kept; the mass the new (straight)
        // partial link does not hold is left in the heap with its momentum.
        const double M = m_[node] + m_[inner];
        const Vec<dim> p = m_[node] * v_.col(node) + m_[inner] * v_.col(inner);
        (after ? arc.last : arc.first) = inner;
        rebuild();
        v_.col(inner) = p / M;
        front_states();
        impulse() -= (M - m_[inner]) * v_.col(inner);
        heap_moment() += (M - m_[inner]) * fs_[f].position;
      } else {
        if (!end.insertable) return {EventAction::Kind::kStop, "the heap has run empty"};
        // A new node comes out of the partial link at distance h from the end node, with its velocity.
        x_.col(outer) = x_.col(node) + h_ * s.direction;
        v_.col(outer) = v_.col(node);
        (after ? arc.last : arc.first) = outer;
        rebuild();
      }
    } else {
      ArcRange& A = arcs_[front.arc_minus];
      ArcRange& B = arcs_[front.arc_plus];
      // e0: the fold reached B's first node (it joins A); e1: it reached A's last node (it joins B).
      const bool to_A = e0 != 0;
      if (to_A && B.num_links() == 0) return {EventAction::Kind::kStop, "the fold has reached the end of the string"};
      if (!to_A && (A.num_links() == 0 || path_of_[A.last] >= 0))
        return {EventAction::Kind::kStop, "the fold has reached the start of the string"};
      // Mass parcels: each link's mass is split between its two nodes (½–½ for a full link, l_A–l_B
      // for the folded one). Moving the fold changes the split of two links; the mass that changes
      // node carries its velocity, so momentum is conserved exactly.
      const int a = A.last, b = B.first;
      const int lo = to_A ? a : a - 1;  // the two links whose split changes: (lo, lo+1), (lo+1, lo+2)
      auto shares = [&](int j) -> std::pair<double, double> {
        // split of link (j, j+1) between its start and end node under the current arcs
        if (arc_of_[j] == arc_of_[j + 1]) return {0.5 * lambda_ * h_, 0.5 * lambda_ * h_};
        return {lambda_ * fs_[f].l_minus, lambda_ * fs_[f].l_plus};
      };
      const auto old0 = shares(lo), old1 = shares(lo + 1);
      Eigen::Vector3d mass;
      Points<dim> mom(dim, 3);
      for (int q = 0; q < 3; ++q) {
        mass[q] = m_[lo + q];
        mom.col(q) = m_[lo + q] * v_.col(lo + q);
      }
      if (to_A) {
        A.last = b;
        B.first = b + 1;
      } else {
        A.last = a - 1;
        B.first = a;
      }
      rebuild();
      front_states();
      const auto new0 = shares(lo), new1 = shares(lo + 1);
      const Points<dim> v_old = v_;
      auto move = [&](int j, std::pair<double, double> before_split, std::pair<double, double> after_split) {
        const double delta = after_split.first - before_split.first;  // change of the start node's share
        const int q = j - lo;
        if (delta < 0) {  // start node gives
          mass[q] += delta;
          mom.col(q) += delta * v_old.col(j);
          mass[q + 1] -= delta;
          mom.col(q + 1) -= delta * v_old.col(j);
        } else {  // end node gives
          mass[q] += delta;
          mom.col(q) += delta * v_old.col(j + 1);
          mass[q + 1] -= delta;
          mom.col(q + 1) -= delta * v_old.col(j + 1);
        }
      };
      move(lo, old0, new0);
      move(lo + 1, old1, new1);
      for (int q = 0; q < 3; ++q)
        if (path_of_[lo + q] < 0 && in_arc(lo + q)) v_.col(lo + q) = mom.col(q) / mass[q];
    }
    ++transfers_;
    break;  // one crossing per event; a simultaneous one is found again right after
  }
  // The new links are brought back to their lengths (a fold's arms are never exactly antiparallel
  // in the discrete state); the kinetic energy the crossing changes is booked.
  const Vec<dim> p_before = [&] {
    Vec<dim> p = Vec<dim>::Zero();
    for (int i = 0; i < n_; ++i)
      if (in_arc(i)) p += m_[i] * v_.col(i);
    return p;
  }();
  front_states();
  project(t);
  front_states();
  Vec<dim> p_after = Vec<dim>::Zero();
  for (int i = 0; i < n_; ++i)
    if (in_arc(i)) p_after += m_[i] * v_.col(i);
  impulse() += p_after - p_before;  // the projection's impulse (through fixed nodes)
  w_remesh_ += kinetic() + potential(ledger) - E_before;
  y = pack(ledger);
  return {EventAction::Kind::kTransfer, {}};
}

template <int dim>
double FrontModel<dim>::heap_mass(std::size_t k) const {
  const bool after = fronts_[k].arc_plus < 0;
  return lambda_ * (after ? chain_.length() - fs_[k].s0 : fs_[k].s0);
}

template <int dim>
double FrontModel<dim>::potential(const Eigen::Ref<const Eigen::VectorXd>& ledger) const {
  // V = −g·∫ λ x ds with full and partial links at their midpoints and the heaps at their first
  // moment. (The dynamics lumps a partial link's mass on its end node; V does not.)
  const Vec<dim> g = gravity();
  double first_moment = g.dot(heap_moment0_ + ledger.template segment<dim>(kLedger + dim));
  for (const ArcRange& arc : arcs_)
    for (int j = arc.first; j < arc.last; ++j) first_moment += lambda_ * h_ * g.dot(0.5 * (x_.col(j) + x_.col(j + 1)));
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    const Front& front = fronts_[k];
    const FrontState& f = fs_[k];
    if (front.kind == FrontKind::kHeap) {
      const HeapEnd end = heap_end(front);
      const double l = end.after ? f.l_minus : f.l_plus;
      first_moment += lambda_ * l * g.dot(0.5 * (x_.col(end.node) + f.position));
    } else {
      const int a = arcs_[front.arc_minus].last, b = arcs_[front.arc_plus].first;
      first_moment += lambda_ * f.l_minus * g.dot(0.5 * (x_.col(a) + f.position)) +
                      lambda_ * f.l_plus * g.dot(0.5 * (x_.col(b) + f.position));
    }
  }
  return -first_moment;
}

template <int dim>
typename FrontModel<dim>::Snapshot FrontModel<dim>::snapshot(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  Snapshot s;
  s.t = t;
  unpack(t, y);
  front_states();
  evaluate(t);
  s.x = x_;
  s.v = v_;
  s.fronts = fs_;
  for (int i = 0; i < n_; ++i) {
    if (!in_arc(i)) continue;
    s.kinetic += 0.5 * m_[i] * v_.col(i).squaredNorm();
    s.momentum += m_[i] * v_.col(i);
    s.moving_mass += m_[i];
    s.support += reaction_.col(i);
  }
  for (const ArcRange& arc : arcs_)
    for (int j = arc.first; j < arc.last; ++j) {
      const double l = (x_.col(j + 1) - x_.col(j)).norm();
      s.max_violation = std::max(s.max_violation, std::abs(l - h_) / h_);
    }
  const Vec<dim> g = gravity();
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    if (fronts_[k].kind != FrontKind::kHeap) continue;
    const double heap = heap_mass(k);
    s.heap_mass += heap;
    s.support += fs_[k].reaction - heap * g;
  }
  const int base = 2 * dim * num_moving_;
  s.potential = potential(y.tail(kLedger + 2 * dim));
  s.w_applied = y[base];
  s.w_shocks = y[base + 1];
  s.w_heaps = y[base + 2];
  s.impulse = y.template segment<dim>(base + kLedger);
  s.heap_moment = heap_moment0_ + y.template segment<dim>(base + kLedger + dim);
  s.w_remesh = w_remesh_;
  return s;
}

template class FrontModel<2>;
template class FrontModel<3>;

}  // namespace chainsim
