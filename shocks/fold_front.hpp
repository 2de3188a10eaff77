#pragma once
/// @file fold_front.hpp
/// A fold front (front_kind.hpp): an internal shock at the bight of a folded string, between the arc
/// before and the arc after it (front_tracker.hpp has the physics, docs/shocks.md the numerics); the
/// split link's bookkeeping is SplitLinkFront's (split_link_front.hpp).
#include "shocks/split_link_front.hpp"

namespace chainsim {

/// A fold (internal shock) between the arc before and the arc after s0.
struct FoldSpec {
  double dissipation = 0;  ///< f, in [0, 1]
  double s0 = 0;           ///< initial material coordinate of the fold (m), in [0, ℓ)
};

template <int dim>
class FoldFront final : public SplitLinkFront<dim> {
 public:
  explicit FoldFront(const FoldSpec& spec);

  /// A fold is a tight bight: its arms leave it along one line. The jump conditions allow a
  /// dissipative kink nowhere else (docs/shocks.md), so a run stops when the arms open wider than
  /// this angle from antiparallel (and a fold that starts wider is refused).
  static constexpr double kMaxOpeningDeg = 20;
  /// The folded link's material (length h) must span its chord |x_b − x_a|. The fold crosses a node
  /// when the chord's component along the fold direction (the bisector of the arms) reaches h: with
  /// arms on one line the chord is then h, with arms within kMaxOpeningDeg of antiparallel at most
  /// h / cos(kMaxOpeningDeg / 2). The run stops when the chord passes that (the fold has come apart,
  /// docs/shocks.md "A fold whose arms turn apart").
  static double max_chord() { return 1 / std::cos(0.5 * kMaxOpeningDeg * kPi / 180); }

  const char* name() const override { return "fold"; }
  const char* placed() const override { return "fold"; }

  void check_initial(const FrontState<dim>& state) const override;
  /// g[0] = l⁺ + kCrossingHysteresis h (the fold reaches arc B's first node), g[1] = l⁻ + kCrossingHysteresis h
  /// (arc A's last). The thresholds lie past the nodes, not on them (as a heap's are moved out, heap_front.cpp):
  /// a crossing leaves the new split link's other partial link at about 0, and a fold placed on a node starts
  /// there, so a fold at rest on a node (a folded chain in free fall, ṡ0 = 0) sits kCrossingHysteresis h from
  /// either threshold instead of on one, where round-off of 1e-17 m decided the crossings (docs/shocks.md,
  /// "A fold at rest on a node"). At a free end of the string both stop kLastPartial h before it (end_margin).
  void crossings(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  void evaluate(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass,
                Points<dim>& force) override;
  /// One: positive while the arms are within kMaxOpeningDeg of antiparallel and the folded link's
  /// material spans its chord.
  int num_checks() const override { return 1; }
  void checks(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const override;
  std::string check_failed(const StringModel<dim>& model, const FrontState<dim>& state, double t,
                           int check) const override;

 private:
  /// `t`: the time of a run's stop (none at the start's refusal).
  std::string opened_message(const FrontState<dim>& state, std::optional<double> t = std::nullopt) const;
  std::string apart_message(const StringModel<dim>& model, const FrontState<dim>& state, double t) const;

  double chord_ = 0;  ///< |x_b − x_a| / h of the folded link
};

}  // namespace chainsim
