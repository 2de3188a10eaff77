// The discrete string as an ODE system: see string_model.hpp.
#include "string_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "mesh/errors.hpp"

namespace chainsim {

namespace {
/// A link shorter than this fraction of its material length is a trial state the model cannot use
/// (the unit vector e_j is undefined): ARKODE retries with a smaller step.
constexpr double kCollapsedLink = 1e-6;
/// The initial projection stops when every link length is right to this relative accuracy, or when
/// Newton's method stalls (round-off of coordinates large against h) below kProjectionStall.
constexpr double kProjectionTolerance = 1e-14;
constexpr double kProjectionStall = 1e-10;
constexpr int kProjectionIterations = 60;
}  // namespace

void StringModelOptions::validate() const {
  require_in_range("solver.stabilization_time", stabilization_time, 0.0, INFINITY);
  require_in_range("solver.slack_tolerance", slack_tolerance, 0.0, 1.0);
  if (backend != "auto") make_tension_backend(backend);  // throws InputError for an unknown name
}

template <int dim>
StringModel<dim>::StringModel(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                              std::vector<PrescribedNode<dim>> prescribed, const StringModelOptions& options)
    : chain_(std::move(chain)), forces_(std::move(forces)), prescribed_(std::move(prescribed)), options_(options) {
  options_.validate();
  // The rows below number link j as unknown j and close the loop through chain_.closed(): one arc.
  // The shock module assembles per arc (ArcBlock) when it splits chains at fronts.
  CHAINSIM_VERIFY(chain_.arcs().size() == 1, "StringModel assembles a single arc");
  const int n = chain_.num_nodes(), L = chain_.num_links();
  // 1. Which nodes are prescribed.
  path_of_.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t k = 0; k < prescribed_.size(); ++k) {
    const int node = prescribed_[k].node;
    if (node < 0 || node >= n)
      throw InputError(fmt::format("prescribed node {} does not exist: the string has nodes 0..{}", node, n - 1));
    if (path_of_[node] >= 0) throw InputError(fmt::format("node {} has two prescribed motions", node));
    CHAINSIM_VERIFY(prescribed_[k].path != nullptr, "a prescribed node needs a path");
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
    }
  }
  for (int j = 0; j < L; ++j)
    if (path_of_[chain_.link_start(j)] >= 0 && path_of_[chain_.link_end(j)] >= 0)
      throw InputError(fmt::format("link {} joins two prescribed nodes ({} and {}): its tension is undetermined; "
                                   "use more nodes",
                                   j, chain_.link_start(j), chain_.link_end(j)));
  // 2. The free nodes, in node order, make the ODE state.
  slot_.assign(static_cast<std::size_t>(n), -1);
  w_ = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (path_of_[i] >= 0) continue;
    slot_[i] = num_free_++;
    w_[i] = 1.0 / chain_.mass(i);
  }
  if (num_free_ == 0) throw InputError("every node of the string is prescribed: nothing to solve");
  // 3. The tension system: one arc per chain arc, pattern assembled once.
  std::vector<int> arc_links;
  std::vector<bool> arc_closed;
  for (const Arc& arc : chain_.arcs()) {
    arc_links.push_back(arc.num_links());
    arc_closed.push_back(arc.closed);
  }
  system_ = std::make_unique<TensionSystem>(arc_links, arc_closed, std::vector<Junction*>{}, options_.backend);
  if (options_.stabilization_time > 0) alpha_ = beta_ = 1.0 / options_.stabilization_time;
  // 4. Workspace.
  for (Points<dim>* p : {&x_, &v_, &a_, &force_, &force_nc_, &tension_force_, &b_}) *p = Points<dim>::Zero(dim, n);
  for (Points<dim>* p : {&dx_, &dv_, &e_}) *p = Points<dim>::Zero(dim, L);
  l_ = Eigen::VectorXd::Zero(L);
}

template <int dim>
Vec<dim> StringModel<dim>::gravity() const {
  for (const auto& force : forces_)
    if (const auto* g = dynamic_cast<const Gravity<dim>*>(force.get())) return g->g();
  return Vec<dim>::Zero();
}

template <int dim>
void StringModel<dim>::unpack(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Points<dim>& x,
                              Points<dim>& v) const {
  const int n = chain_.num_nodes();
  x.resize(dim, n);
  v.resize(dim, n);
  const int voff = dim * num_free_;
  for (int i = 0; i < n; ++i) {
    const int k = slot_[i];
    if (k >= 0) {
      x.col(i) = y.template segment<dim>(dim * k);
      v.col(i) = y.template segment<dim>(voff + dim * k);
    } else {
      const EndPath<dim>& path = *prescribed_[static_cast<std::size_t>(path_of_[i])].path;
      x.col(i) = path.position(t);
      v.col(i) = path.velocity(t);
    }
  }
}

template <int dim>
void StringModel<dim>::links(const Points<dim>& x, const Points<dim>& v) {
  const int L = chain_.num_links();
  for (int j = 0; j < L; ++j) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    dx_.col(j) = x.col(b) - x.col(a);
    dv_.col(j) = v.col(b) - v.col(a);
    const double l = dx_.col(j).norm();
    if (!(l > kCollapsedLink * chain_.link_length(j)) || !std::isfinite(l))
      throw RecoverableError(fmt::format("link {} has collapsed to length {:g}", j, l));
    l_[j] = l;
    e_.col(j) = dx_.col(j) / l;
  }
}

template <int dim>
void StringModel<dim>::assemble_matrix() {
  // Row j: T_{j−1} w_a (e_{j−1}·e_j) − T_j (w_a + w_b) + T_{j+1} w_b (e_j·e_{j+1}); the coupling of
  // link j with the next link j+1 goes through their shared node b = link_end(j).
  const int L = chain_.num_links();
  const bool closed = chain_.closed();
  for (int j = 0; j < L; ++j) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    system_->add_diagonal(j, -(w_[a] + w_[b]));
    if (j + 1 < L || closed) {
      const int next = j + 1 < L ? j + 1 : 0;
      system_->set_coupling(j, w_[b] * e_.col(j).dot(e_.col(next)));
    }
  }
}

template <int dim>
double StringModel<dim>::evaluate(double t, const Points<dim>& x, const Points<dim>& v) {
  const int n = chain_.num_nodes(), L = chain_.num_links();
  // 1. Applied forces; b_i = F_i / m_i for free nodes, the prescribed acceleration otherwise.
  const NodeState<dim> state{t, x, v, chain_.masses()};
  force_.setZero();
  force_nc_.setZero();
  for (const auto& force : forces_) force->add_force(state, force->conservative() ? force_ : force_nc_);
  for (int i = 0; i < n; ++i) {
    if (path_of_[i] < 0)
      b_.col(i) = w_[i] * (force_.col(i) + force_nc_.col(i));
    else
      b_.col(i) = prescribed_[static_cast<std::size_t>(path_of_[i])].path->acceleration(t);
  }
  // 2. Link geometry and the tension system.
  links(x, v);
  system_->zero();
  assemble_matrix();
  const double beta2 = beta_ * beta_;
  for (int j = 0; j < L; ++j) {
    const int a = chain_.link_start(j), b = chain_.link_end(j);
    const double h = chain_.link_length(j), l = l_[j];
    const double stab = 2 * alpha_ * dx_.col(j).dot(dv_.col(j)) + beta2 * 0.5 * (l * l - h * h);
    system_->rhs(j) = -dv_.col(j).squaredNorm() / l - e_.col(j).dot(b_.col(b) - b_.col(a)) - stab / l;
  }
  system_->add_junction_rows(t);
  const Eigen::VectorXd& T = system_->solve(t);
  // 3. Accelerations and the power of everything not booked in V.
  tension_force_.setZero();
  for (int j = 0; j < L; ++j) {
    tension_force_.col(chain_.link_start(j)) += T[j] * e_.col(j);
    tension_force_.col(chain_.link_end(j)) -= T[j] * e_.col(j);
  }
  double power = 0;
  for (int i = 0; i < n; ++i) {
    if (path_of_[i] < 0) {
      a_.col(i) = b_.col(i) + w_[i] * tension_force_.col(i);
      power += force_nc_.col(i).dot(v.col(i));
    } else {
      a_.col(i) = b_.col(i);
      power += (chain_.mass(i) * a_.col(i) - force_.col(i) - tension_force_.col(i)).dot(v.col(i));
    }
  }
  return power;
}

template <int dim>
void StringModel<dim>::rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
  unpack(t, y, x_, v_);
  const double power = evaluate(t, x_, v_);
  const int n = chain_.num_nodes(), voff = dim * num_free_;
  for (int i = 0; i < n; ++i) {
    const int k = slot_[i];
    if (k < 0) continue;
    ydot.template segment<dim>(dim * k) = v_.col(i);
    ydot.template segment<dim>(voff + dim * k) = a_.col(i);
  }
  ydot[size() - 1] = power;
}

template <int dim>
double StringModel<dim>::make_consistent(double t0) {
  const int n = chain_.num_nodes(), L = chain_.num_links();
  Points<dim>& x = chain_.positions();
  Points<dim>& v = chain_.velocities();
  for (const auto& p : prescribed_) {
    x.col(p.node) = p.path->position(t0);
    v.col(p.node) = p.path->velocity(t0);
  }
  const Points<dim> x_start = x;
  // Newton's method for g_j(x) = |Δx_j| − h_j = 0 along δx = W Gᵀ ν: the matrix is the tension
  // matrix A = −G W Gᵀ, so A ν = g gives the minimal mass-weighted correction.
  auto apply_correction = [&](Points<dim>& target, const Eigen::VectorXd& nu) {
    for (int j = 0; j < L; ++j) {
      const int a = chain_.link_start(j), b = chain_.link_end(j);
      target.col(a) -= w_[a] * nu[j] * e_.col(j);
      target.col(b) += w_[b] * nu[j] * e_.col(j);
    }
  };
  // Coordinates far from the origin, or links far shorter than the coordinates, limit how well a
  // link length can be represented at all: stall detection starts at that round-off level.
  double h_min = INFINITY;
  for (int j = 0; j < L; ++j) h_min = std::min(h_min, chain_.link_length(j));
  const double roundoff = 64 * std::numeric_limits<double>::epsilon() * x.cwiseAbs().maxCoeff() / h_min;
  const double stall = std::max(kProjectionStall, roundoff);
  double violation = 0;
  try {
    int iteration = 0;
    double previous = INFINITY;
    for (;; ++iteration) {
      links(x, v);
      violation = 0;
      for (int j = 0; j < L; ++j)
        violation = std::max(violation, std::abs(l_[j] - chain_.link_length(j)) / chain_.link_length(j));
      if (violation <= kProjectionTolerance || (violation < stall && violation > 0.5 * previous)) break;
      previous = violation;
      if (iteration == kProjectionIterations || !std::isfinite(violation))
        throw InputError(fmt::format(
            "the initial shape cannot be fitted to the link lengths: after {} projection steps a link is still "
            "off by {:.3g} of its length (are the fixed or driven ends further apart than the string is long?)",
            iteration, violation));
      system_->zero();
      assemble_matrix();
      for (int j = 0; j < L; ++j) system_->rhs(j) = l_[j] - chain_.link_length(j);
      apply_correction(x, system_->solve(t0));
    }
    // Velocities: one linear projection onto e_j·Δv_j = 0.
    links(x, v);
    system_->zero();
    assemble_matrix();
    for (int j = 0; j < L; ++j) system_->rhs(j) = e_.col(j).dot(dv_.col(j));
    apply_correction(v, system_->solve(t0));
  } catch (const RecoverableError& e) {
    throw InputError(fmt::format("the initial shape is degenerate: {}", e.what()));
  } catch (const NumericalError& e) {
    throw InputError(fmt::format("the initial shape cannot be fitted to the link lengths: {}", e.what()));
  }
  double moved = 0;
  for (int i = 0; i < n; ++i) moved = std::max(moved, (x.col(i) - x_start.col(i)).norm());
  return moved;
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
typename StringModel<dim>::Snapshot StringModel<dim>::snapshot(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  Snapshot s;
  s.t = t;
  unpack(t, y, s.x, s.v);
  s.power = evaluate(t, s.x, s.v);
  s.a = a_;
  s.tension = system_->solution();
  const NodeState<dim> state{t, s.x, s.v, chain_.masses()};
  for (int i = 0; i < chain_.num_nodes(); ++i) s.kinetic += 0.5 * chain_.mass(i) * s.v.col(i).squaredNorm();
  for (const auto& force : forces_)
    if (force->conservative()) s.potential += force->potential(state);
  s.work = y[size() - 1];
  for (int j = 0; j < chain_.num_links(); ++j) {
    s.max_violation = std::max(s.max_violation, std::abs(l_[j] - chain_.link_length(j)) / chain_.link_length(j));
    s.max_rate_violation = std::max(s.max_rate_violation, std::abs(e_.col(j).dot(dv_.col(j))));
  }
  return s;
}

template <int dim>
double StringModel<dim>::max_constraint_violation(double t, const Eigen::Ref<const Eigen::VectorXd>& y) const {
  auto position = [&](int i) -> Vec<dim> {
    const int k = slot_[i];
    if (k >= 0) return y.template segment<dim>(dim * k);
    return prescribed_[static_cast<std::size_t>(path_of_[i])].path->position(t);
  };
  double worst = 0;
  for (int j = 0; j < chain_.num_links(); ++j) {
    const double h = chain_.link_length(j);
    const double l = (position(chain_.link_end(j)) - position(chain_.link_start(j))).norm();
    worst = std::max(worst, std::abs(l - h) / h);
  }
  return worst;
}

template <int dim>
void StringModel<dim>::check_slack(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  unpack(t, y, x_, v_);
  evaluate(t, x_, v_);
  const Eigen::VectorXd& T = system_->solution();
  // Compare with a physical tension scale too, so that a string whose exact tension is zero (free
  // fall, uniform motion) is not reported slack for round-off: λ (|g| ℓ + max |v|²).
  double v2_max = 0;
  for (int i = 0; i < v_.cols(); ++i) v2_max = std::max(v2_max, v_.col(i).squaredNorm());
  const double physical = chain_.density() * (gravity().norm() * chain_.length() + v2_max);
  const double scale = std::max(T.cwiseAbs().maxCoeff(), physical);
  int worst = 0;
  for (int j = 1; j < T.size(); ++j)
    if (T[j] < T[worst]) worst = j;
  if (T[worst] < -options_.slack_tolerance * scale)
    throw NumericalError(fmt::format("slack at t = {:.9g} s: link {} (s = {:.6g} m from node 0) has tension "
                                     "T = {:.6g} N < 0 (largest |T| = {:.6g} N); an inextensible string cannot "
                                     "push, so the model does not apply",
                                     t, worst, chain_.link_midpoint(worst), T[worst], scale),
                         t);
}

template class StringModel<2>;
template class StringModel<3>;

}  // namespace chainsim
