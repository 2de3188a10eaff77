#pragma once
// A canonical problem on the string solver at a given f and mesh (the other parameters the paper's
// defaults): shared by the front-tracking convergence and hard-case tests.
#include "cases/canonical/canonical_string.hpp"

namespace chainsim::test {

inline StringCaseSetup setup_for(Problem problem, double f, int nodes) {
  StringCaseSetup s;
  s.problem = problem;
  s.chain.dissipation = f;
  s.nodes = nodes;
  return s;
}

}  // namespace chainsim::test
