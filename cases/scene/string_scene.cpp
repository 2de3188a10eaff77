// String scenes, step 3: SceneSpec -> StringModel (build_string_scene, scene.hpp), for a scene
// without fronts.
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_build.hpp"

namespace chainsim {

using scene_build::at_key;

template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec) {
  CHAINSIM_VERIFY(!spec.has_fronts(), "a scene with fronts is built by build_front_scene");
  scene_build::front_stop_indices(spec);  // refuses a stop event on a front the scene lacks
  scene_build::SceneParts<dim> parts = scene_build::build_scene_parts<dim>(spec);
  StringScene<dim> scene;
  scene.characteristic_time = parts.characteristic_time;
  const StringModelOptions& mo = parts.model;
  scene.solver = parts.solver;
  scene.output = spec.output.select;

  // The model, its initial state projected onto the constraints now, so that a shape that cannot be
  // fitted (e.g. fixed ends further apart than the string is long) is refused before the run.
  std::string fit_key = "shape";
  if (spec.start.prescribed()) fit_key = "ends.start";
  if (spec.end.prescribed()) fit_key = "ends.end";
  scene.model = at_key(spec, fit_key, [&] {
    auto model = std::make_unique<StringModel<dim>>(std::move(parts.chain), std::move(parts.forces),
                                                    std::move(parts.prescribed), mo);
    model->make_consistent(0.0);
    return model;
  });
  return scene;
}

template StringScene<2> build_string_scene<2>(const SceneSpec&);
template StringScene<3> build_string_scene<3>(const SceneSpec&);

}  // namespace chainsim
