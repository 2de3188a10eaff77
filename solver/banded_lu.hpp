#pragma once
/// @file banded_lu.hpp
/// A band LU factorisation of a sparse matrix whose unknowns, put in a given order, couple only
/// within a few places of each other: the Newton matrices of a string (string_jacobian.hpp), whose
/// unknowns ordered along the string (node, link, node, …; a closed string folded so that its last
/// node sits beside its first) lie within a bandwidth of a few nodes whatever the number of links.
///
/// The matrix is stored and factored by SUNDIALS (SUNBandMatrix and SUNLinSol_Band: LU with partial
/// pivoting inside the band, O(n · ml · (ml + mu)) per factorisation, O(n · (2 ml + mu)) per solve);
/// this class holds the order, the assembly into the band and the permutations of the solves.
#include <memory>
#include <vector>

namespace chainsim {

class BandedLU {
 public:
  BandedLU();
  ~BandedLU();
  BandedLU(const BandedLU&) = delete;
  BandedLU& operator=(const BandedLU&) = delete;

  /// The order: unknown k goes to place position[k] (a permutation of 0 … n−1), and the band has
  /// `lower` sub- and `upper` super-diagonals in that order (every entry added later must lie in it).
  /// Allocates only when n or the bandwidths change. Zeroes the matrix.
  void reset(std::vector<int> position, int lower, int upper);
  /// Zeroes the matrix (same order and band).
  void zero();
  /// A(row, col) += value, in the unknowns' own numbering.
  void add(int row, int col, double value) {
    const int r = position_[static_cast<std::size_t>(row)], c = position_[static_cast<std::size_t>(col)];
    columns_[static_cast<std::size_t>(c)][r - c] += value;
  }
  /// Factors the assembled matrix. False if a pivot is exactly zero (the matrix is singular).
  bool factor();
  /// x = A⁻¹ b in place (`rhs` holds b on entry), with the last successful factor().
  void solve(double* rhs);

  int size() const { return static_cast<int>(position_.size()); }
  int lower_bandwidth() const { return lower_; }
  int upper_bandwidth() const { return upper_; }
  const std::vector<int>& position() const { return position_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<int> position_;
  std::vector<double*> columns_;  // column j of the band, pointing at its diagonal entry
  int lower_ = 0, upper_ = 0;
};

}  // namespace chainsim
