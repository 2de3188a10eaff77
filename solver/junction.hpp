#pragma once
/// @file junction.hpp
/// Interface only: a junction joins arcs (or an arc and a reservoir) and adds rows to the tension
/// system (DESIGN.md §3, shocks/).
///
/// The string solver of this version builds models without junctions; the shock module implements
/// this interface for internal shocks (dissipation f), table contact with a heap, reservoirs and
/// ends with their own dynamics. A junction
///   1. declares, once, how many extra unknowns it brings (e.g. the front speed ṡ0, a reaction
///      force) and every (row, col) entry it will write — in its own rows and in the rows of the
///      arcs' end links it couples (declare_entries), so the pattern is assembled once;
///   2. looks up the positions of those entries in the assembled pattern (bind);
///   3. at every right-hand side adds its values and right-hand sides (add_rows) after the model
///      has written the arcs' link rows;
///   4. reads its unknowns back after the solve (read_solution).
/// Its extra rows equal its extra unknowns, so the system stays square. Sign convention: "+" is
/// the side of larger material coordinate s (DESIGN.md §1).
#include <string>

#include "tension_system.hpp"

namespace chainsim {

class Junction {
 public:
  virtual ~Junction() = default;
  /// A short name used in messages ("internal shock at s0 = 0.3 m").
  virtual std::string name() const = 0;
  /// Number of extra unknowns (and rows) this junction adds; they follow all arcs' link unknowns.
  virtual int num_unknowns() const { return 0; }
  /// Declares every entry it will write (builder.first_own_unknown() is its first unknown).
  virtual void declare_entries(TensionPatternBuilder& builder) = 0;
  /// Finds its entries' slots in the assembled system (TensionSystem::slot), once.
  virtual void bind(TensionSystem& system) = 0;
  /// Adds its values (TensionSystem::value(slot) +=) and right sides (rhs(row) +=) at time t (s).
  virtual void add_rows(double t, TensionSystem& system) const = 0;
  /// Reads its unknowns from system.solution() after a solve.
  virtual void read_solution(const TensionSystem& /*system*/) {}
};

}  // namespace chainsim
