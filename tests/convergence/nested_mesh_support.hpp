#pragma once
// The difference between two nested meshes of an open string, shared by the convergence tests that refine by
// halving the links (N and 2N − 1 nodes): node i of the coarser mesh is the material point of node 2i of the finer.
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "mesh/chain.hpp"

namespace chainsim::test {

/// The distances between the same material points of the two meshes.
struct NestedDifference {
  double largest = 0;  ///< the largest distance (m)
  double rms = 0;      ///< the root mean square over the coarser mesh's nodes (m)
};

/// Node i of `coarse` against node 2i of `fine`, for every node of `coarse` (`fine` has 2 coarse.cols() − 1 nodes).
template <int dim>
NestedDifference nested_mesh_difference(const Points<dim>& coarse, const Points<dim>& fine) {
  NestedDifference d;
  double sum = 0;
  for (Eigen::Index i = 0; i < coarse.cols(); ++i) {
    const double distance = (coarse.col(i) - fine.col(2 * i)).norm();
    sum += distance * distance;
    d.largest = std::max(d.largest, distance);
  }
  d.rms = coarse.cols() > 0 ? std::sqrt(sum / static_cast<double>(coarse.cols())) : 0.0;
  return d;
}

}  // namespace chainsim::test
