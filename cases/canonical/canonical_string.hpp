#pragma once
/// @file canonical_string.hpp
/// The paper's three chain problems solved with the string solver and its front tracking
/// (shocks/front_tracker.hpp), in the
/// paper's geometry (2D, x horizontal, y up, g = −g e_y) or in a general variant:
///
///   falling  the part above the table (material s ∈ [0, y], free end at s = 0 on top) ends on the
///            table y = 0 at x0 = 0 at t = 0; the heap holds s > y and lies on the table, and the
///            contact slides along the table where the string meets it. Variants: released tilted
///            by `tilt_deg` from the vertical (a straight line), and curved by `bend_deg` (a circular
///            arc whose tangent turns from tilt_deg at the table to tilt_deg + bend_deg at the top).
///   folded   node 0 fixed at the origin; the resting arm hangs to the fold at depth y; the moving
///            arm goes up from the fold to the free end (loaded by F e_y). Variant: the moving arm
///            released tilted by `tilt_deg` (ends apart: it swings while it falls).
///   sliding  the heap on the table feeds the string through the hole x0 = 0; the hanging part
///            s ∈ [ℓ − y, ℓ] (free end at s = ℓ). Variant: the hanging part released tilted by
///            `tilt_deg` (it swings while it slides). η0 = 0 starts on the exact branch
///            y = a t²/2 (a = g/(3 + 2f)) at y = 2 h.
///
/// η = y/ℓ, P = the vertical force of all supports (table/plane with the heap, or the fixed end).
#include <optional>

#include <nlohmann/json.hpp>

#include "cases/reduced/reduced_models.hpp"
#include "shocks/front_tracker.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

struct StringCaseSetup {
  Problem problem = Problem::kFalling;
  ChainParameters chain;
  int nodes = 101;                ///< nodes of the whole string (N + 1), >= 4
  double eps = 0.01;              ///< cutoff (as ReducedSetup)
  std::optional<double> eta0;     ///< as ReducedSetup (defaults: falling 1, folded 0, sliding 0)
  double force = 0;               ///< folded: upward end force F (N)
  double tilt_deg = 0;            ///< general variant (see the file comment); 0 = the paper's geometry
  double bend_deg = 0;            ///< falling only: curved release (see the file comment)
  double t_max_over_t0 = 50.0;    ///< safety stop
  double frame_interval = 0;      ///< s between recorded frames of the string's nodes (0: only the start and stop)
  IntegratorOptions integrator = default_integrator();
  static IntegratorOptions default_integrator();
  /// The reduced model's setup of the same problem (its own default integrator).
  ReducedSetup reduced() const;
  void validate() const;
};

/// A string-solver run of a canonical problem: the run plus η, η' = dη/dξ and P/P0 per sample.
struct StringCaseRun {
  RunSummary run;
  std::vector<double> t, eta, eta_dot, P;  ///< t (s), η, dη/dt (1/s), P (N)
  std::vector<Frame<2>> frames;  ///< the nodes at the start, every frame_interval and the stop (solver time)
  double t_offset = 0;  ///< time of the string's start on the reduced solution (sliding from η0 = 0)
  nlohmann::json summary;
};

/// Builds and runs the problem. Throws InputError for a bad setup.
StringCaseRun solve_string_case(const StringCaseSetup& setup);

/// The string solver and the reduced ODE on the same problem (`chainsim compare`). The reduced model
/// is integrated with its default method and max_step t0/5000, and evaluated at the string's sample
/// times by cubic Hermite interpolation (η, dη/dt). Summary keys (besides the string run's):
///   t_stop_over_t0, t_stop_over_t0_reduced, rel_err_t_stop,
///   max_abs_err_eta      max over the string's samples of |η_string(t) − η_reduced(t)|,
///   max_rel_err_P        max over the samples of |P_string − P_reduced| / max(|P_reduced|, P0) at equal η
///                        (P_reduced at the string's η, by Hermite interpolation in t of the reduced
///                        run at the time it has that η), or at equal t where η is not monotone,
///   energy_residual      the string run's relative energy ledger residual,
///   nodes, wall_s (string solver), wall_s_reduced.
struct Comparison {
  StringCaseRun string;
  ReducedRun reduced{CsvTable(series_columns()), {}};
  nlohmann::json summary;
};
Comparison compare_with_reduced(const StringCaseSetup& setup);

}  // namespace chainsim
