#pragma once
/// @file slack_module.hpp
/// The module of unilateral links ([solver] slack = "allow"; docs/model.md "Slack and snap-taut"):
/// what a string whose links may go slack adds to the one discrete string (string_module.hpp). The
/// string keeps its one arc; its tension solve becomes a complementarity problem (StringModel::
/// solve_tensions) and its slack links are flagged (StringModel::link_slack). The module adds
///   - one root function, the smallest gap (h_j − l_j)/h_j of the slack links (StringModel::slack_gap),
///     at which the string snaps taut (StringModel::snap);
///   - the ledgers W_snap (J, ≤ 0: the energy the snaps dissipated, given to the string with its sign),
///     W_snap_supports (J: the work of the supports' impulses at snaps, zero at fixed ends) and the
///     impulse of all external forces (the momentum ledger p − p0 − impulse, closed across snaps: the
///     impulsive tensions are internal);
///   - W_links (J, numerical): −∫ Σ T_j dl_j/dt dt, the tensions' work on the links' changes of length
///     (a released link that returns to its length before going slack is pulled back by the drift
///     control: its loss is booked here, so the energy ledger closes to the integration error);
///   - the recorded quantity snaps (series.csv): the number of snaps so far.
/// A string with fronts (heaps, folds) keeps its front tracker: this module wraps it, passes its layout,
/// masses, forces, ledgers, events and fronts through, and adds its own ledgers and root function after
/// the tracker's (docs/model.md §9 "Slack next to a front"). A link bent over an edge is unilateral like the
/// others (its length l⁻ + l⁺, the edge taking its impulses); after a snap the fronts' checks are evaluated on
/// the new state, and one that the snap made fail (an edge that would now pull) stops the run (docs/model.md §9
/// "Slack over an edge").
#include <memory>

#include "string_module.hpp"

namespace chainsim {

/// The module of unilateral links around `inner`, the fronts' module (nullptr: a string without
/// fronts). It passes the inner module's layout, masses, forces, ledgers and events through and adds
/// its own after them; the fronts' events are handled first at an event that finds both.
template <int dim>
std::unique_ptr<StringModule<dim>> make_slack_module(std::unique_ptr<StringModule<dim>> inner);

}  // namespace chainsim
