#pragma once
/// @file banded_lu.hpp
/// A band LU factorisation of a sparse matrix whose unknowns, put in a given order, couple only
/// within a few places of each other: the Newton matrices of a string (string_jacobian.hpp), whose
/// unknowns ordered along the string (node, link, node, …; a closed string folded so that its last
/// node sits beside its first) lie within a bandwidth of a few nodes whatever the number of links.
///
/// With K ≥ both bandwidths (K = 6, 8, 12 or 16), the ordered unknowns read in consecutive groups of K
/// make a block-tridiagonal matrix (an entry within K places of the diagonal is at most one group off
/// it), factored by the block Thomas algorithm of the quadratic elements (BlockTridiagonal,
/// quadratic_string.hpp: fixed-size K×K blocks, each pivot block inverted with partial pivoting;
/// the unknowns past n in the last group are identity rows): O(n K²) per factorisation, O(n K) per
/// solve, in unrolled fixed-size products. A wider band goes to SUNDIALS (SUNBandMatrix and
/// SUNLinSol_Band: LU with partial pivoting inside the band). This class holds the order, the
/// assembly and the permutations of the solves.
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
  void add(int row, int col, double value) { entry(row, col) += value; }
  /// The storage of A(row, col), in the unknowns' own numbering: valid until the next reset(), so an
  /// assembly whose entries come in a fixed sequence can keep the addresses.
  double& entry(int row, int col) {
    const int r = position_[static_cast<std::size_t>(row)], c = position_[static_cast<std::size_t>(col)];
    if (block_ > 0) {
      const int br = r / block_, bc = c / block_;
      return blocks_[static_cast<std::size_t>(3 * br + bc - br + 1)][(c - bc * block_) * block_ + r - br * block_];
    }
    return columns_[static_cast<std::size_t>(c)][r - c];
  }
  /// Factors the assembled matrix. False if it is singular (a zero pivot; with blocks, a pivot block
  /// whose scaled inverse exceeds 1e13).
  bool factor();
  /// x = A⁻¹ b in place (`rhs` holds b on entry), with the last successful factor().
  void solve(double* rhs);

  int size() const { return static_cast<int>(position_.size()); }
  int lower_bandwidth() const { return lower_; }
  int upper_bandwidth() const { return upper_; }
  /// The size of the blocks of the block-tridiagonal factorisation (0: SUNDIALS' band LU).
  int block_size() const { return block_; }
  const std::vector<int>& position() const { return position_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<int> position_;
  std::vector<double*> columns_;  // SUNDIALS' band: column j, pointing at its diagonal entry
  std::vector<double*> blocks_;   // blocks: (lower, diagonal, upper) of each block row, column-major
  int lower_ = 0, upper_ = 0, block_ = 0;
};

}  // namespace chainsim
