// The tight fold's line constraint: see fold_contact.hpp.
#include "fold_contact.hpp"

#include <cmath>

#include "solver/errors.hpp"

namespace chainsim {

template <int dim>
FoldContact<dim>::FoldContact(int p, int r, int o, std::vector<Link> links, double h)
    : p_(p), r_(r), o_(o), links_(std::move(links)), h_(h) {
  CHAINSIM_VERIFY(h > 0 && p != r && r != o && p != o, "fold contact: bad nodes or link length");
}

template <int dim>
void FoldContact<dim>::declare_entries(TensionPatternBuilder& builder) {
  first_ = builder.first_own_unknown();
  for (const Link& link : links_)
    for (int k = 0; k < kRows; ++k) {
      builder.add_entry(link.unknown, first_ + k);
      builder.add_entry(first_ + k, link.unknown);
    }
  for (int k = 0; k < kRows; ++k)
    for (int m = 0; m < kRows; ++m) builder.add_entry(first_ + k, first_ + m);
}

template <int dim>
void FoldContact<dim>::bind(TensionSystem& system) {
  link_slots_.assign(links_.size(), {});
  for (std::size_t l = 0; l < links_.size(); ++l)
    for (int k = 0; k < kRows; ++k)
      link_slots_[l][static_cast<std::size_t>(k)] = {system.slot(links_[l].unknown, first_ + k),
                                                     system.slot(first_ + k, links_[l].unknown)};
  for (int k = 0; k < kRows; ++k)
    for (int m = 0; m < kRows; ++m)
      own_slots_[static_cast<std::size_t>(k)][static_cast<std::size_t>(m)] = system.slot(first_ + k, first_ + m);
}

template <int dim>
typename FoldContact<dim>::V3 FoldContact<dim>::lift(const Vec<dim>& a) {
  V3 b = V3::Zero();
  b.template head<dim>() = a;
  return b;
}

template <int dim>
Vec<dim> FoldContact<dim>::drop(const V3& a) {
  return a.template head<dim>();
}

template <int dim>
void FoldContact<dim>::set_geometry(const Points<dim>& x) {
  u_ = lift(x.col(o_) - x.col(r_));
  w_ = lift(x.col(r_) - x.col(p_));
  if constexpr (dim == 2) {
    q_[0] = V3::UnitZ();
  } else {
    // An orthonormal pair normal to the reference link (any pair: the constraint is u × w = 0).
    const V3 t = w_.normalized();
    const V3 helper = std::abs(t.x()) < 0.9 ? V3::UnitX() : V3::UnitY();
    q_[0] = t.cross(helper).normalized();
    q_[1] = t.cross(q_[0]);
  }
  for (int k = 0; k < kRows; ++k) {
    const V3& q = q_[static_cast<std::size_t>(k)];
    g_[k] = q.dot(u_.cross(w_)) / h_;
    const V3 du = w_.cross(q) / h_;  // ∂g/∂u
    const V3 dw = q.cross(u_) / h_;  // ∂g/∂w
    grad_[static_cast<std::size_t>(k)] = {drop(-dw), drop(dw - du), drop(du)};  // p, r, o
  }
}

template <int dim>
typename FoldContact<dim>::Rows FoldContact<dim>::apply(const Points<dim>& z) const {
  Rows out;
  for (int k = 0; k < kRows; ++k) {
    const auto& gr = grad_[static_cast<std::size_t>(k)];
    out[k] = gr[0].dot(z.col(p_)) + gr[1].dot(z.col(r_)) + gr[2].dot(z.col(o_));
  }
  return out;
}

template <int dim>
typename FoldContact<dim>::Rows FoldContact<dim>::rate(const Points<dim>& v) const {
  return apply(v);
}

template <int dim>
typename FoldContact<dim>::Rows FoldContact<dim>::curvature_term(const Points<dim>& v) const {
  const V3 du = lift(v.col(o_) - v.col(r_)), dw = lift(v.col(r_) - v.col(p_));
  Rows out;
  for (int k = 0; k < kRows; ++k) out[k] = 2 * q_[static_cast<std::size_t>(k)].dot(du.cross(dw)) / h_;
  return out;
}

template <int dim>
void FoldContact<dim>::add_force(const Eigen::VectorXd& solution, Points<dim>& force) const {
  const std::array<int, 3> nodes{p_, r_, o_};
  for (int k = 0; k < kRows; ++k) {
    const double mu = solution[first_ + k];
    for (int c = 0; c < 3; ++c)
      force.col(nodes[static_cast<std::size_t>(c)]) -= mu * grad_[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)];
  }
}

template class FoldContact<2>;
template class FoldContact<3>;

}  // namespace chainsim
