// One run of a string scene: see scene_run.hpp.
#include "cases/scene/scene_run.hpp"

#include "cases/scene/front_scene.hpp"

#include <cmath>

namespace chainsim {

template <int dim>
SceneRun<dim>::SceneRun(const SceneSpec& spec) : scene_(build_string_scene<dim>(spec)) {
  solver_ = std::make_unique<StringSolver<dim>>(*scene_.model, scene_.solver);
}

template <int dim>
SceneRun<dim>::~SceneRun() = default;
template <int dim>
SceneRun<dim>::SceneRun(SceneRun&&) noexcept = default;
template <int dim>
SceneRun<dim>& SceneRun<dim>::operator=(SceneRun&&) noexcept = default;

template <int dim>
std::optional<NumericalError> SceneRun<dim>::run(const std::function<void(double)>& on_step) {
  if (on_step)
    solver_->on_step = [&on_step](double t, const Eigen::VectorXd&) { on_step(t); };
  else
    solver_->on_step = nullptr;
  std::optional<NumericalError> failure;
  try {
    solver_->run();
  } catch (const NumericalError& e) {
    failure = e;
  }
  solver_->on_step = nullptr;
  return failure;
}

template <int dim>
nlohmann::json SceneRun<dim>::description() const {
  return scene_.has_fronts() ? scene_.description : nlohmann::json();
}

template <int dim>
nlohmann::json SceneRun<dim>::summary() const {
  nlohmann::json j = front_summary(scene_, solver_->summary());
  // With slack = "allow": how many links snapped taut and what the snaps dissipated, at the last frame
  // (its time `ledger_t`; the same numbers as energy.csv's last row), so that a run whose links went slack
  // says so ("detected" is the first slack of the other policies).
  const std::vector<Frame<dim>>& frames = solver_->frames();
  if (solver_->summary().slack_policy == SlackPolicy::kAllow && !frames.empty()) {
    const LedgerValues& terms = frames.back().terms;
    nlohmann::json& slack = j["slack"];
    slack["snaps"] = static_cast<long long>(std::llround(terms["snaps"]));
    slack["W_snap"] = terms["W_snap"];
    slack["W_snap_supports"] = terms["W_snap_supports"];
    slack["ledger_t"] = frames.back().t;
  }
  return j;
}

template <int dim>
void SceneRun<dim>::write(const std::filesystem::path& dir, const nlohmann::json& summary) const {
  write(RunDirectory(dir), summary);
}

template <int dim>
void SceneRun<dim>::write(const RunDirectory& dir, const nlohmann::json& summary) const {
  solver_->write_outputs(dir.path(), scene_.output, &summary);
}

template <int dim>
void SceneRun<dim>::stream(const RunDirectory& dir) {
  solver_->stream_outputs(dir.path(), scene_.output);
}

template class SceneRun<2>;
template class SceneRun<3>;

}  // namespace chainsim
