// String scenes, step 3: SceneSpec -> StringModel (build_string_scene, scene.hpp), the one builder of
// scenes with and without fronts (the fronts' part: build_front_model, front_scene.cpp).
#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_build.hpp"

namespace chainsim {

using scene_build::at_key;

template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec) {
  if (!spec.has_fronts()) scene_build::front_stop_indices(spec);  // refuses a stop event on a front the scene lacks
  scene_build::SceneParts<dim> parts = scene_build::build_scene_parts<dim>(spec);
  StringScene<dim> scene;
  scene.characteristic_time = parts.characteristic_time;
  scene.solver = parts.solver;
  scene.output = spec.output.select;
  scene.description = {{"model", "string"}, {"fronts", nlohmann::json::array()}, {"num_fronts", 0}};

  if (spec.has_fronts()) {
    scene.model = build_front_model<dim>(spec, parts, scene);
  } else {
    // The model, its initial state projected onto the constraints now, so that a shape that cannot be
    // fitted (e.g. fixed ends further apart than the string is long) is refused before the run.
    std::string fit_key = "shape";
    if (spec.start.prescribed()) fit_key = "ends.start";
    if (spec.end.prescribed()) fit_key = "ends.end";
    const StringModelOptions& mo = parts.model;
    scene.model = at_key(spec, fit_key, [&] {
      auto model = std::make_unique<StringModel<dim>>(std::move(parts.chain), std::move(parts.forces),
                                                      std::move(parts.prescribed), mo);
      model->make_consistent(0.0);
      return model;
    });
  }
  // The model's part of the description, read back from it as the run's summary reads it.
  RunSummary built;
  describe_model(*scene.model, built);
  scene.description.update(model_json(built));
  return scene;
}

template StringScene<2> build_string_scene<2>(const SceneSpec&);
template StringScene<3> build_string_scene<3>(const SceneSpec&);

}  // namespace chainsim
