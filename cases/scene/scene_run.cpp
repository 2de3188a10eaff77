// One run of a string scene: see scene_run.hpp.
#include "cases/scene/scene_run.hpp"

#include "cases/scene/front_scene.hpp"

namespace chainsim {

template <int dim>
SceneRun<dim>::SceneRun(const SceneSpec& spec) {
  if (spec.has_fronts()) {
    fronts_ = std::make_unique<FrontScene<dim>>(build_front_scene<dim>(spec));
    model_ = std::move(fronts_->model);
    options_ = fronts_->solver;
    output_ = fronts_->output;
  } else {
    StringScene<dim> scene = build_string_scene<dim>(spec);
    model_ = std::move(scene.model);
    options_ = scene.solver;
    output_ = scene.output;
  }
  solver_ = std::make_unique<StringSolver<dim>>(*model_, options_);
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
  return fronts_ ? fronts_->description : nlohmann::json();
}

template <int dim>
nlohmann::json SceneRun<dim>::summary() const {
  if (fronts_) return front_summary(*fronts_, solver_->summary());
  nlohmann::json j = to_json(solver_->summary());
  j["model"] = "string";
  j["fronts"] = nlohmann::json::array();  // none built: no fronts, no root functions
  j["num_fronts"] = 0;
  return j;
}

template <int dim>
void SceneRun<dim>::write(const std::filesystem::path& dir, const nlohmann::json& summary) const {
  write(RunDirectory(dir), summary);
}

template <int dim>
void SceneRun<dim>::write(const RunDirectory& dir, const nlohmann::json& summary) const {
  solver_->write_outputs(dir.path(), output_, &summary);
}

template class SceneRun<2>;
template class SceneRun<3>;

}  // namespace chainsim
