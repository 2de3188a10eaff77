#pragma once
/// @file chain.hpp
/// The Lagrangian discretization of an inextensible string (docs/string_solver.md, Discretization).
///
/// A chain of n material nodes x_i (i = 0..n-1) joined by rigid links. Link j joins node j and
/// node j+1; on a closed string link n-1 joins node n-1 and node 0. Link j has material length h_j
/// (m), so the material coordinate (arc length from node 0) of node i is s_i = h_0 + ... + h_{i-1}.
/// Masses are lumped: m_i = λ (h_{i-1} + h_i) / 2, and the end nodes of an open string carry
/// λ h / 2 of their single link, so that Σ m_i = λ ℓ exactly.
///
/// The dimension d (2 or 3) is a compile-time parameter: a 2D chain stores 2 components per node
/// and pays for no third one.
///
/// Arcs: a chain is cut into arcs (contiguous runs of nodes and links with no junction inside). In
/// this version every chain is one arc; the shock module splits chains at moving fronts and moves
/// nodes between arcs (mesh/transfer.hpp, later). An arc owns a contiguous block of link unknowns in
/// the tension system.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>

#include "mesh/errors.hpp"  // header-only use: InputError

namespace chainsim {

/// π, for the shapes and their tests.
inline constexpr double kPi = 3.14159265358979323846;

/// A point or vector in R^dim.
template <int dim>
using Vec = Eigen::Matrix<double, dim, 1>;

/// A point or vector as messages show it, six significant digits: "[0.04, -0.3]" (a zero as 0, never -0).
template <int dim>
std::string show_point(const Vec<dim>& x) {
  std::string out = "[";
  for (int d = 0; d < dim; ++d) out += fmt::format("{}{:g}", d > 0 ? ", " : "", x[d] == 0 ? 0.0 : x[d]);
  return out + "]";
}

/// dim × n matrix, one column per node.
template <int dim>
using Points = Eigen::Matrix<double, dim, Eigen::Dynamic>;

/// A contiguous run of nodes and links with no junction inside.
struct Arc {
  int first_node = 0;   ///< index of its first node in the chain
  int num_nodes = 0;    ///< number of nodes
  bool closed = false;  ///< closed loop: its last link joins its last node to its first
  int first_link = 0;   ///< index of its first link in the chain
  int num_links() const { return closed ? num_nodes : num_nodes - 1; }
};

template <int dim>
class Chain {
  static_assert(dim == 2 || dim == 3, "chainsim strings live in 2D or 3D");

 public:
  using Vector = Vec<dim>;
  static constexpr int kDim = dim;

  /// A chain of density λ (kg/m) with the given link material lengths (m). An open chain with L links
  /// has L+1 nodes; a closed one has L nodes and needs L >= 3. Positions and velocities start at 0.
  Chain(double density, std::vector<double> link_lengths, bool closed)
      : density_(density), h_(std::move(link_lengths)), closed_(closed) {
    if (!(density_ > 0) || !std::isfinite(density_))
      throw InputError(fmt::format("string.density = {:g} is out of range: allowed density > 0", density_));
    if (h_.empty() || (closed_ && h_.size() < 3))
      throw InputError(fmt::format("a {} string needs at least {} links, got {}", closed_ ? "closed" : "open",
                                   closed_ ? 3 : 1, h_.size()));
    length_ = 0;
    s_.assign(h_.size() + 1, 0.0);
    for (double h : h_) {
      if (!(h > 0) || !std::isfinite(h))
        throw InputError(fmt::format("link length = {:g} is out of range: allowed h > 0", h));
      length_ += h;
    }
    for (std::size_t j = 0; j < h_.size(); ++j) s_[j + 1] = s_[j] + h_[j];
    const int n = num_nodes();
    mass_ = Eigen::VectorXd::Zero(n);
    for (int j = 0; j < num_links(); ++j) {
      mass_[link_start(j)] += 0.5 * density_ * h_[j];
      mass_[link_end(j)] += 0.5 * density_ * h_[j];
    }
    x_ = Points<dim>::Zero(dim, n);
    v_ = Points<dim>::Zero(dim, n);
    arcs_.push_back(Arc{0, n, closed_, 0});
  }

  /// A chain of `links` equal links of total length `length`.
  static Chain uniform(double density, double length, int links, bool closed) {
    return Chain(density, std::vector<double>(static_cast<std::size_t>(links), length / links), closed);
  }

  int num_nodes() const { return closed_ ? num_links() : num_links() + 1; }
  int num_links() const { return static_cast<int>(h_.size()); }
  bool closed() const { return closed_; }
  /// Linear density λ (kg/m).
  double density() const { return density_; }
  /// Material length ℓ = Σ h_j (m).
  double length() const { return length_; }
  /// Material length h_j of link j (m).
  double link_length(int j) const { return h_[static_cast<std::size_t>(j)]; }
  const std::vector<double>& link_lengths() const { return h_; }
  /// Lumped mass m_i of node i (kg).
  double mass(int i) const { return mass_[i]; }
  const Eigen::VectorXd& masses() const { return mass_; }
  double total_mass() const { return mass_.sum(); }

  /// First node of link j.
  int link_start(int j) const { return j; }
  /// Second node of link j (node 0 for the closing link of a closed chain).
  int link_end(int j) const { return j + 1 == num_nodes() ? 0 : j + 1; }

  /// Material coordinate s_i of node i (m from node 0 along the string).
  double node_coordinate(int i) const { return s_[static_cast<std::size_t>(i)]; }
  /// Material coordinate of the midpoint of link j (m).
  double link_midpoint(int j) const { return node_coordinate(j) + 0.5 * link_length(j); }

  const std::vector<Arc>& arcs() const { return arcs_; }

  /// Node positions (m), one column per node.
  Points<dim>& positions() { return x_; }
  const Points<dim>& positions() const { return x_; }
  /// Node velocities (m/s), one column per node.
  Points<dim>& velocities() { return v_; }
  const Points<dim>& velocities() const { return v_; }

  /// Current chord length |x_{j+1} - x_j| of link j (m).
  double chord(int j) const { return (x_.col(link_end(j)) - x_.col(link_start(j))).norm(); }
  /// max_j |chord_j - h_j| / h_j: how far the positions are from the link constraints.
  double max_length_violation() const {
    double worst = 0;
    for (int j = 0; j < num_links(); ++j) worst = std::max(worst, std::abs(chord(j) - h_[j]) / h_[j]);
    return worst;
  }

 private:
  double density_;
  std::vector<double> h_;
  bool closed_;
  double length_ = 0;
  std::vector<double> s_;  // s_[i]: material coordinate of node i (s_[n] = ℓ on a closed chain)
  Eigen::VectorXd mass_;
  Points<dim> x_, v_;
  std::vector<Arc> arcs_;
};

}  // namespace chainsim
