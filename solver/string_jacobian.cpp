// The exact linearisation of the string and its Newton systems: see string_jacobian.hpp.
#include "string_jacobian.hpp"
#include "banded_lu.hpp"
#include "quadratic_string.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "forces.hpp"
#include "string_model.hpp"
#include "tension_system.hpp"

namespace chainsim {

template <int dim>
struct StringJacobian<dim>::Factor {
  SparsePattern pattern;
  /// (row, column) of each entry of the assembly sequence and its slot in `pattern`: the sequence is
  /// the same at every call for one layout, so only the values are summed into their slots.
  std::vector<int> rows, cols, slot;
  std::vector<double> values;
  SparseFactorization lu;
  /// Factors the matrix of `entries` (duplicates summed), redoing the pattern and its symbolic
  /// analysis only when the sequence of (row, column) changed. Throws RecoverableError if singular.
  void factorize(int n, const std::vector<Eigen::Triplet<double>>& entries);
  /// Factors A with its pattern and values as the tension system holds them.
  void factorize(const SparsePattern& a_pattern, const std::vector<double>& a_values);
};

template <int dim>
void StringJacobian<dim>::Factor::factorize(int n, const std::vector<Eigen::Triplet<double>>& entries) {
  bool same = lu.analyzed() && pattern.n == n && rows.size() == entries.size();
  for (std::size_t k = 0; same && k < entries.size(); ++k)
    same = entries[k].row() == rows[k] && entries[k].col() == cols[k];
  if (!same) {
    SpMat m(n, n);
    m.setFromTriplets(entries.begin(), entries.end());
    m.makeCompressed();
    pattern.n = n;
    pattern.col_ptr.assign(m.outerIndexPtr(), m.outerIndexPtr() + n + 1);
    pattern.row_index.assign(m.innerIndexPtr(), m.innerIndexPtr() + m.nonZeros());
    rows.resize(entries.size());
    cols.resize(entries.size());
    slot.resize(entries.size());
    for (std::size_t k = 0; k < entries.size(); ++k) {
      rows[k] = entries[k].row();
      cols[k] = entries[k].col();
      slot[k] = pattern.find(rows[k], cols[k]);
    }
    lu.analyze(pattern);
  }
  values.assign(pattern.row_index.size(), 0.0);
  for (std::size_t k = 0; k < entries.size(); ++k) values[static_cast<std::size_t>(slot[k])] += entries[k].value();
  if (!lu.factor(values.data()).ok) {
    rows.clear();  // analyse afresh next time
    throw RecoverableError("a Newton matrix of the string is singular");
  }
}

template <int dim>
void StringJacobian<dim>::Factor::factorize(const SparsePattern& a_pattern, const std::vector<double>& a_values) {
  if (!lu.analyzed() || pattern.n != a_pattern.n || pattern.col_ptr != a_pattern.col_ptr ||
      pattern.row_index != a_pattern.row_index) {
    pattern = a_pattern;
    lu.analyze(pattern);
  }
  if (!lu.factor(a_values.data()).ok) {
    pattern.n = -1;  // analyse afresh next time
    throw RecoverableError("a Newton matrix of the string is singular");
  }
}

template <int dim>
StringJacobian<dim>::StringJacobian(StringModel<dim>& model)
    : model_(model), factor_(std::make_unique<Factor>()), a_factor_(std::make_unique<Factor>()) {}

template <int dim>
StringJacobian<dim>::~StringJacobian() = default;

template <int dim>
void StringJacobian<dim>::linearize(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
  using Mat = Eigen::Matrix<double, dim, dim>;
  using V = Vec<dim>;
  StringModel<dim>& m = model_;
  CHAINSIM_VERIFY(m.system_ != nullptr, "the linearisation needs a tension system");
  m.unpack_state(t, y);
  m.evaluate_current(t);  // e, l, Δx, Δv, b and the tensions at (t, y)
  const Chain<dim>& chain = m.chain_;
  nv_ = dim * m.num_free_;
  nt_ = m.system_->size();
  const Eigen::VectorXd& T = m.system_->solution();
  const int L = chain.num_links();
  std::vector<int> prev(static_cast<std::size_t>(L), -1);
  std::vector<int> link_to, link_from;  // with a module: the link of the arcs ending, starting at a node
  if (m.module_) {
    link_to.assign(static_cast<std::size_t>(chain.num_nodes()), -1);
    link_from = link_to;
  }
  m.for_each_link([&](int j, int, int next) {
    if (next >= 0) prev[static_cast<std::size_t>(next)] = j;
    if (m.module_) {
      link_to[static_cast<std::size_t>(chain.link_end(j))] = j;
      link_from[static_cast<std::size_t>(chain.link_start(j))] = j;
    }
  });

  std::vector<Eigen::Triplet<double>> p, qx, qv, wg;
  p.reserve(static_cast<std::size_t>(4 * dim * dim * L));
  qx.reserve(static_cast<std::size_t>(6 * dim * L));
  qv.reserve(static_cast<std::size_t>(2 * dim * L));
  wg.reserve(static_cast<std::size_t>(2 * dim * L));
  // Adds the block `value` at (row node, column node) when both are free.
  auto add_block = [&](std::vector<Eigen::Triplet<double>>& out, int row_node, int col_node, const Mat& value) {
    const int r = m.slot_[static_cast<std::size_t>(row_node)], c = m.slot_[static_cast<std::size_t>(col_node)];
    if (r < 0 || c < 0) return;
    for (int q = 0; q < dim; ++q)
      for (int s = 0; s < dim; ++s) out.emplace_back(dim * r + q, dim * c + s, value(q, s));
  };
  // Adds g·δΔx_k (g a row) to row u: +g at the end node of link k, −g at its start node.
  auto add_link_gradient = [&](std::vector<Eigen::Triplet<double>>& out, int u, int k, const V& g) {
    const int ka = m.slot_[static_cast<std::size_t>(chain.link_start(k))];
    const int kb = m.slot_[static_cast<std::size_t>(chain.link_end(k))];
    for (int s = 0; s < dim; ++s) {
      if (kb >= 0) out.emplace_back(u, dim * kb + s, g[s]);
      if (ka >= 0) out.emplace_back(u, dim * ka + s, -g[s]);
    }
  };
  auto tension_of = [&](int link) { return T[m.link_unknown_[static_cast<std::size_t>(link)]]; };
  auto projector = [&](int link) -> Mat {
    const V e = m.e_.col(link);
    return Mat::Identity() - e * e.transpose();
  };
  const double alpha = m.alpha_, beta2 = m.beta2_;  // β² as the evaluation capped it

  m.for_each_link([&](int j, int u, int next) {
    const int a = chain.link_start(j), b = chain.link_end(j);
    const double l = m.l_[j], h = chain.link_length(j), wa = m.w_[a], wb = m.w_[b];
    const V e = m.e_.col(j), dx = m.dx_.col(j), dv = m.dv_.col(j);
    const Mat Pi = projector(j);
    // P: the tension force ±T_j e_j with δe_j = Π_j δΔx_j / l_j.
    const Mat K = (T[u] / l) * Pi;
    add_block(p, a, b, wa * K);
    add_block(p, a, a, -wa * K);
    add_block(p, b, b, -wb * K);
    add_block(p, b, a, wb * K);
    // Q_j = δr_j − (δA T)_j.
    const double s = 2 * alpha * dx.dot(dv) + beta2 * 0.5 * (l * l - h * h);
    const V db = m.b_.col(b) - m.b_.col(a);
    V gx = ((dv.squaredNorm() + s) / (l * l)) * e - Pi * db / l - (2 * alpha / l) * dv - (beta2 / l) * dx;
    const V gv = -(2 / l) * (dv + alpha * dx);
    if (next >= 0) {
      const double Tn = tension_of(next);
      gx -= (wb * Tn / l) * (Pi * m.e_.col(next));
      add_link_gradient(qx, u, next, -(wb * Tn / m.l_[next]) * (projector(next) * e));
    }
    const int pj = prev[static_cast<std::size_t>(j)];
    if (pj >= 0) {
      const double Tp = tension_of(pj);
      gx -= (wa * Tp / l) * (Pi * m.e_.col(pj));
      add_link_gradient(qx, u, pj, -(wa * Tp / m.l_[pj]) * (projector(pj) * e));
    }
    add_link_gradient(qx, u, j, gx);
    add_link_gradient(qv, u, j, gv);
    // W Gᵀ: column u holds −w_a e_j at node a and +w_b e_j at node b.
    const int ka = m.slot_[static_cast<std::size_t>(a)], kb = m.slot_[static_cast<std::size_t>(b)];
    for (int q = 0; q < dim; ++q) {
      if (ka >= 0) wg.emplace_back(dim * ka + q, u, -wa * e[q]);
      if (kb >= 0) wg.emplace_back(dim * kb + q, u, wb * e[q]);
    }
  });
  // The module's loads (a front's partial-link mass on an arc's end node k and its jump-condition
  // forces), F_k(x, v) and m_k(x, v): a_k = w_k (F_k + m_k g + … − tension forces), so at frozen
  // tensions δa_k = w_k D δy with D = ∂F_k + (g − a_k) ∂m_k (g the uniform field, whose force m_k g
  // follows the mass). D enters P (positions), Pv (velocities) and, through the accelerations of the
  // links at k (their constraint rows read ∓e_j·a_k), Qx and Qv.
  std::vector<Eigen::Triplet<double>> pv;
  if (m.module_ && m.module_->has_load_derivatives()) {
    std::vector<LoadDerivative<dim>>& loads = load_derivatives_;
    loads.clear();
    m.module_->load_derivatives(m, loads);
    const V g = m.uniform_field();
    for (const LoadDerivative<dim>& d : loads) {
      const int k = d.node, rk = m.slot_[static_cast<std::size_t>(k)], ci = m.slot_[static_cast<std::size_t>(d.of)];
      if (rk < 0 || ci < 0) continue;
      const Mat D = m.w_[k] * (d.force + (g - m.a_.col(k)) * d.mass);
      add_block(d.velocity ? pv : p, k, d.of, D);
      // The links at k: the row of the one ending there reads −e_j·δa_k (r = −e_j·Δb − …), of the one
      // starting there +e_j·δa_k.
      for (int side = 0; side < 2; ++side) {
        const int j = (side ? link_from : link_to)[static_cast<std::size_t>(k)];
        if (j < 0) continue;
        const Eigen::Matrix<double, 1, dim> row = (side ? 1.0 : -1.0) * m.e_.col(j).transpose() * D;
        const int u = m.link_unknown_[static_cast<std::size_t>(j)];
        for (int q = 0; q < dim; ++q) (d.velocity ? qv : qx).emplace_back(u, dim * ci + q, row[q]);
      }
    }
  }
  bool new_pattern = assemble(P_, nv_, nv_, p, slots_[0]);
  new_pattern |= assemble(Pv_, nv_, nv_, pv, slots_[4]);
  new_pattern |= assemble(Qx_, nt_, nv_, qx, slots_[1]);
  new_pattern |= assemble(Qv_, nt_, nv_, qv, slots_[2]);
  new_pattern |= assemble(WGt_, nv_, nt_, wg, slots_[3]);
  // A: the tension matrix as assembled by the model (compressed columns); factored alone only if
  // apply() needs it.
  a_values_ = m.system_->values();
  const SparsePattern& a = m.system_->pattern();
  if (a_pattern_.n != a.n || a_pattern_.col_ptr != a.col_ptr || a_pattern_.row_index != a.row_index) a_pattern_ = a;
  a_factored_ = false;
  exact_ = m.newton_solver_exact();
  const std::string& choice = m.options_.linear_solver;
  banded_ = choice == "banded" || (choice == "auto" && !m.module_);
  if (banded_ && (new_pattern || !band_ || band_->size() != nv_ + nt_ || ordered_slots_ != m.slot_ ||
                  ordered_links_ != m.link_unknown_)) {
    order_along_string();
    ordered_slots_ = m.slot_;
    ordered_links_ = m.link_unknown_;
  }
}

template <int dim>
bool StringJacobian<dim>::assemble(BlockMat& out, int rows, int cols, const std::vector<Eigen::Triplet<double>>& entries,
                                   Slots& s) {
  bool same = out.rows() == rows && out.cols() == cols && s.rows.size() == entries.size();
  for (std::size_t k = 0; same && k < entries.size(); ++k)
    same = entries[k].row() == s.rows[k] && entries[k].col() == s.cols[k];
  if (same) {  // the values into the slots, duplicates summed in the order of the entries
    std::fill(out.valuePtr(), out.valuePtr() + out.nonZeros(), 0.0);
    for (std::size_t k = 0; k < entries.size(); ++k) out.valuePtr()[s.slot[k]] += entries[k].value();
    return false;
  }
  out.resize(rows, cols);
  out.setFromTriplets(entries.begin(), entries.end());
  out.makeCompressed();
  s.rows.resize(entries.size());
  s.cols.resize(entries.size());
  s.slot.resize(entries.size());
  for (std::size_t k = 0; k < entries.size(); ++k) {
    s.rows[k] = entries[k].row();
    s.cols[k] = entries[k].col();
    const int* first = out.innerIndexPtr() + out.outerIndexPtr()[s.rows[k]];  // row-major: rows are outer
    const int* last = out.innerIndexPtr() + out.outerIndexPtr()[s.rows[k] + 1];
    s.slot[k] = static_cast<int>(std::lower_bound(first, last, s.cols[k]) - out.innerIndexPtr());
  }
  return true;
}

template <int dim>
void StringJacobian<dim>::order_along_string() {
  const StringModel<dim>& m = model_;
  const Chain<dim>& chain = m.chain_;
  const int N = chain.num_nodes(), L = chain.num_links();
  // Node i has the key 2i, link j (from node i) 2i + 1: along an open string, or along the arcs of
  // one, every coupling (a node with its neighbours and its two links, a link with the nodes of its
  // neighbours) is within a few keys. A closed string's last link couples node n−1 with node 0: its
  // keys are folded, 0, 2n−1, 1, 2n−2, … → 0, 1, 2, 3, …, so that every coupling is within twice as many.
  const bool fold = chain.closed() && !m.module_;
  auto place = [&](int key) { return !fold ? key : key < N ? 2 * key : 2 * (2 * N - 1 - key) + 1; };
  std::vector<int> start(static_cast<std::size_t>(2 * N + 1), 0);
  for (int i = 0; i < N; ++i)
    if (m.slot_[static_cast<std::size_t>(i)] >= 0) start[static_cast<std::size_t>(place(2 * i)) + 1] = dim;
  for (int j = 0; j < L; ++j)
    if (m.link_unknown_[static_cast<std::size_t>(j)] >= 0)
      start[static_cast<std::size_t>(place(2 * chain.link_start(j) + 1)) + 1] = 1;
  for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  std::vector<int> position(static_cast<std::size_t>(nv_ + nt_), -1);
  for (int i = 0; i < N; ++i) {
    const int k = m.slot_[static_cast<std::size_t>(i)];
    if (k >= 0)
      for (int q = 0; q < dim; ++q)
        position[static_cast<std::size_t>(dim * k + q)] = start[static_cast<std::size_t>(place(2 * i))] + q;
  }
  for (int j = 0; j < L; ++j) {
    const int u = m.link_unknown_[static_cast<std::size_t>(j)];
    if (u >= 0) position[static_cast<std::size_t>(nv_ + u)] = start[static_cast<std::size_t>(place(2 * chain.link_start(j) + 1))];
  }
  int lower = 0, upper = 0;
  for_each_entry(1.0, [&](int r, int c, double) {
    const int d = position[static_cast<std::size_t>(r)] - position[static_cast<std::size_t>(c)];
    lower = std::max(lower, d);
    upper = std::max(upper, -d);
  });
  if (!band_) band_ = std::make_unique<BandedLU>();
  band_->reset(std::move(position), lower, upper);
  band_entries_.clear();  // the storage of each entry, in the sequence of for_each_entry
  for_each_entry(1.0, [&](int r, int c, double) { band_entries_.push_back(&band_->entry(r, c)); });
}

template <int dim>
template <class Emit>
void StringJacobian<dim>::for_each_entry(double gamma, Emit&& emit) const {
  for (int i = 0; i < nv_; ++i) emit(i, i, 1.0);
  auto add = [&](const BlockMat& block, int row0, int col0, double scale) {
    for (int c = 0; c < block.outerSize(); ++c)
      for (BlockMat::InnerIterator it(block, c); it; ++it)
        emit(row0 + static_cast<int>(it.row()), col0 + static_cast<int>(it.col()), scale * it.value());
  };
  add(P_, 0, 0, -gamma * gamma);
  add(Pv_, 0, 0, -gamma);
  add(WGt_, 0, nv_, gamma);
  add(Qx_, nv_, 0, gamma);
  add(Qv_, nv_, 0, 1.0);
  const SparsePattern& a = a_pattern_;  // −A
  for (int c = 0; c < a.n; ++c)
    for (int k = a.col_ptr[static_cast<std::size_t>(c)]; k < a.col_ptr[static_cast<std::size_t>(c) + 1]; ++k)
      emit(nv_ + a.row_index[static_cast<std::size_t>(k)], nv_ + c, -a_values_[static_cast<std::size_t>(k)]);
}

template <int dim>
Eigen::MatrixXd StringJacobian<dim>::augmented_matrix() const {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(nv_ + nt_, nv_ + nt_);
  for_each_entry(gamma_, [&](int r, int c, double v) { out(r, c) += v; });
  return out;
}

template <int dim>
int StringJacobian<dim>::lower_bandwidth() const {
  return banded_ ? band_->lower_bandwidth() : 0;
}

template <int dim>
int StringJacobian<dim>::upper_bandwidth() const {
  return banded_ ? band_->upper_bandwidth() : 0;
}

template <int dim>
Eigen::VectorXd StringJacobian<dim>::apply(const Eigen::Ref<const Eigen::VectorXd>& d) const {
  Eigen::VectorXd out(d.size());
  apply(d, out);
  return out;
}

template <int dim>
void StringJacobian<dim>::apply(const Eigen::Ref<const Eigen::VectorXd>& d, Eigen::Ref<Eigen::VectorXd> out) const {
  const auto dx = d.head(nv_), dv = d.segment(nv_, nv_);
  Eigen::VectorXd w = Qx_ * dx + Qv_ * dv;
  if (!a_factored_) {
    a_factor_->factorize(a_pattern_, a_values_);
    a_factored_ = true;
  }
  a_factor_->lu.solve(w.data());
  out.setZero();
  out.head(nv_) = dv;
  out.segment(nv_, nv_) = P_ * dx + Pv_ * dv - WGt_ * w;
}

template <int dim>
void StringJacobian<dim>::factor(double gamma) {
  gamma_ = gamma;
  if (banded_) {
    band_->zero();
    std::size_t k = 0;
    for_each_entry(gamma, [&](int, int, double v) { *band_entries_[k++] += v; });
    if (!band_->factor()) throw RecoverableError("a Newton matrix of the string is singular");
    return;
  }
  std::vector<Eigen::Triplet<double>>& tr = entries_;
  tr.clear();
  tr.reserve(static_cast<std::size_t>(nv_ + P_.nonZeros() + Pv_.nonZeros() + WGt_.nonZeros() + Qx_.nonZeros() + Qv_.nonZeros()) +
             a_values_.size());
  for_each_entry(gamma, [&](int r, int c, double v) { tr.emplace_back(r, c, v); });
  factor_->factorize(nv_ + nt_, tr);
}

template <int dim>
void StringJacobian<dim>::solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> z) const {
  CHAINSIM_VERIFY(r.size() >= 2 * nv_ && z.size() == r.size(), "the Newton system has the state's size");
  const auto rx = r.head(nv_), rv = r.segment(nv_, nv_);
  Eigen::VectorXd& sol = work_;
  sol.resize(nv_ + nt_);
  auto head = sol.head(nv_);  // rv + γ P rx, −Qx rx: the products summed in place (no temporaries)
  auto tail = sol.tail(nt_);
  head = rv;
  head.noalias() += gamma_ * (P_ * rx);
  tail.setZero();
  tail.noalias() -= Qx_ * rx;
  if (banded_)
    band_->solve(sol.data());
  else
    factor_->lu.solve(sol.data());
  z.segment(nv_, nv_) = sol.head(nv_);
  z.head(nv_) = rx + gamma_ * sol.head(nv_);
  z.tail(r.size() - 2 * nv_) = r.tail(r.size() - 2 * nv_);
}

// --- the string's Newton solver (OdeSystem) ------------------------------------------------------
template <int dim>
void StringModel<dim>::newton_setup(double t, const Eigen::Ref<const Eigen::VectorXd>& y, bool relinearize,
                                    double gamma) {
  if (quadratic_) {  // the elements' own Newton systems (quadratic_string.hpp)
    if (relinearize) {
      unpack_state(t, y);
      evaluate_current(t);
      quadratic_->linearize(x_, v_, alpha_, beta2_);
    }
    quadratic_->newton_factor(gamma);
    return;
  }
  if (!bends_.empty())
    throw InputError("an implicit method cannot run a string bent over an edge (its linearisation is not written): "
                     "choose an explicit method");
  if (!jacobian_) jacobian_ = std::make_shared<StringJacobian<dim>>(*this);
  const bool stale = jacobian_->velocity_unknowns() != dim * num_free_ ||
                     jacobian_->tension_unknowns() != (system_ ? system_->size() : 0);
  if (relinearize)
    jacobian_->linearize(t, y);
  else if (stale)
    throw RecoverableError("the string's linearisation is from before its layout changed");
  jacobian_->factor(gamma);
}

template <int dim>
void StringModel<dim>::newton_solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> z) {
  if (quadratic_) {
    const int nv = dim * num_free_;
    Points<dim> rx = Points<dim>::Zero(dim, chain_.num_nodes()), rv = rx, zv;
    for (int i = 0; i < chain_.num_nodes(); ++i) {
      const int k = slot_[i];
      if (k < 0) continue;
      rx.col(i) = r.template segment<dim>(dim * k);
      rv.col(i) = r.template segment<dim>(nv + dim * k);
    }
    quadratic_->newton_solve(rx, rv, zv);
    const double gamma = quadratic_->newton_gamma();
    for (int i = 0; i < chain_.num_nodes(); ++i) {
      const int k = slot_[i];
      if (k < 0) continue;
      z.template segment<dim>(nv + dim * k) = zv.col(i);
      z.template segment<dim>(dim * k) = rx.col(i) + gamma * zv.col(i);
    }
    z.tail(r.size() - 2 * nv) = r.tail(r.size() - 2 * nv);  // the ledgers: identity rows
    return;
  }
  CHAINSIM_VERIFY(jacobian_ && jacobian_->velocity_unknowns() == dim * num_free_,
                  "newton_setup() comes before newton_solve()");
  jacobian_->solve(r, z);
}

template <int dim>
bool StringModel<dim>::jacobian_times(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> Jv) {
  if (!jacobian_ || !jacobian_->exact() || jacobian_->velocity_unknowns() != dim * num_free_) return false;
  jacobian_->apply(v, Jv);
  return true;
}

template <int dim>
bool StringModel<dim>::newton_solver_exact() const {
  if (!system_ || (module_ && !module_->has_load_derivatives())) return false;
  for (const auto& force : forces_)
    if (!dynamic_cast<const UniformField<dim>*>(force.get()) && !dynamic_cast<const EndLoad<dim>*>(force.get())) return false;
  return true;
}

template <int dim>
double StringModel<dim>::explicit_stiffness() const {
  if (!system_) return 0.0;
  double h_min = INFINITY;
  for_each_link([&](int j, int, int) { h_min = std::min(h_min, chain_.link_length(j)); });
  return chain_.length() / h_min;
}

template class StringJacobian<2>;
template class StringJacobian<3>;
template void StringModel<2>::newton_setup(double, const Eigen::Ref<const Eigen::VectorXd>&, bool, double);
template void StringModel<3>::newton_setup(double, const Eigen::Ref<const Eigen::VectorXd>&, bool, double);
template void StringModel<2>::newton_solve(const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd>);
template void StringModel<3>::newton_solve(const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd>);
template bool StringModel<2>::jacobian_times(const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd>);
template bool StringModel<3>::jacobian_times(const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd>);
template bool StringModel<2>::newton_solver_exact() const;
template bool StringModel<3>::newton_solver_exact() const;
template double StringModel<2>::explicit_stiffness() const;
template double StringModel<3>::explicit_stiffness() const;

}  // namespace chainsim
