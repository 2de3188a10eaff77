// [solver], [output], [stop] and the top-level model key: how the scene runs (parse_sections.hpp).
#include <algorithm>
#include <limits>

#include "cases/scene/parse_sections.hpp"
#include "solver/integrator.hpp"
#include "solver/string_model.hpp"

namespace chainsim::scene_parse {

void parse_solver(const Section& top, Context& ctx) {
  auto& so = ctx.spec.solver;
  Section s(subtable(top, "solver"), "solver", ctx,
            {"method", "rtol", "atol", "max_step", "initial_step", "max_steps", "stabilization_time", "backend", "linear_solver",
             "check_slack", "slack_tolerance", "slack", "snap_restitution", "kinks", "kink_turn", "kink_window",
             "max_wall_s"},
            {{"t_end", "in [stop]"}, {"output_interval", "as interval in [output]"}, {"vtk", "as formats in [output]"}});
  // Each value is checked by the option struct that owns its range, one field at a time.
  // The method is checked once, here at its key; the other fields by their ranges alone.
  auto integrator = [&](const char* key, auto set) {
    s.located(key, key, [&] {
      IntegratorOptions o;
      set(o);
      o.validate_numbers();
    });
  };
  so.method = s.string("method").value_or(so.method);
  s.located("method", "method", [&] {
    IntegratorOptions o;
    o.method = so.method;
    o.validate_method();
  });
  so.rtol = s.number("rtol").value_or(so.rtol);
  integrator("rtol", [&](IntegratorOptions& o) { o.rtol = so.rtol; });
  so.atol = s.number("atol").value_or(so.atol);
  integrator("atol", [&](IntegratorOptions& o) { o.atol = so.atol; });
  so.max_step = s.number("max_step").value_or(so.max_step);
  integrator("max_step", [&](IntegratorOptions& o) { o.max_step = so.max_step; });
  so.initial_step = s.number("initial_step").value_or(so.initial_step);
  integrator("initial_step", [&](IntegratorOptions& o) { o.initial_step = so.initial_step; });
  so.max_steps =
      static_cast<long>(s.integer_in("max_steps", 1, std::numeric_limits<long>::max()).value_or(so.max_steps));
  integrator("max_steps", [&](IntegratorOptions& o) { o.max_steps = so.max_steps; });
  auto model = [&](const char* key, auto set) {
    s.located(key, key, [&] {
      StringModelOptions o;
      set(o);
      o.validate();
    });
  };
  so.stabilization_time = s.number("stabilization_time");
  if (so.stabilization_time)
    model("stabilization_time", [&](StringModelOptions& o) { o.stabilization_time = *so.stabilization_time; });
  so.backend = s.string("backend").value_or(so.backend);
  model("backend", [&](StringModelOptions& o) { o.backend = so.backend; });
  so.linear_solver = s.choice("linear_solver", {"auto", "banded", "klu"}, so.linear_solver);
  const std::optional<bool> check_slack = s.boolean("check_slack");
  so.slack = s.choice("slack", {"stop", "warn", "ignore", "allow"}, so.slack);
  if (s.has("check_slack") && s.has("slack"))
    s.fail("check_slack", fmt::format("solver.check_slack = {} and solver.slack = {} both say what a slack link does: "
                                      "give one of them (check_slack = true is slack = \"stop\", false is slack = "
                                      "\"ignore\")",
                                      s.text("check_slack"), s.text("slack")));
  if (check_slack) so.slack = *check_slack ? "stop" : "ignore";
  so.slack_tolerance = s.number("slack_tolerance").value_or(so.slack_tolerance);
  model("slack_tolerance", [&](StringModelOptions& o) { o.slack_tolerance = so.slack_tolerance; });
  so.snap_restitution = s.number("snap_restitution").value_or(so.snap_restitution);
  model("snap_restitution", [&](StringModelOptions& o) { o.snap_restitution = so.snap_restitution; });
  if (so.slack == "allow") {
    IntegratorOptions method;
    method.method = so.method;
    if (method.implicit_method())
      s.fail("method", fmt::format("solver.method = \"{}\" is implicit, and implicit methods do not meet solver.slack = "
                                   "\"allow\" (their Newton systems know no slack link): use an explicit method "
                                   "(\"auto\", \"erk8\", ...)",
                                   so.method));
  } else if (s.has("snap_restitution")) {
    s.fail("snap_restitution", fmt::format("solver.snap_restitution = {} applies only with solver.slack = \"allow\"",
                                           s.text("snap_restitution")));
  }
  // Kinks inserted where they form (docs/model.md §9, "Inserting a kink front where a kink forms").
  so.kinks = s.choice("kinks", {"off", "insert"}, so.kinks);
  so.kink_turn = s.number_in("kink_turn", so.kink_turn, 1, 179);
  so.kink_window = s.positive("kink_window");
  if (so.kinks != "insert")
    for (const char* key : {"kink_turn", "kink_window"})
      if (s.has(key))
        s.fail(key, fmt::format("solver.{} = {} applies only with solver.kinks = \"insert\"", key, s.text(key)));
  so.max_wall_s = s.positive("max_wall_s");
}

void parse_output(const Section& top, Context& ctx) {
  auto& out = ctx.spec.output;
  Section s(subtable(top, "output"), "output", ctx, {"interval", "fields", "formats", "vtk_encoding", "max_megabytes"});
  out.interval = s.positive("interval").value_or(out.interval);
  out.select.max_megabytes = s.positive("max_megabytes").value_or(out.select.max_megabytes);
  if (s.has("fields")) {
    const auto fields = s.string_list("fields", {"nodes", "tension", "energy", "forces", "stats"});
    auto has = [&](const char* f) { return std::find(fields.begin(), fields.end(), f) != fields.end(); };
    out.select.nodes = has("nodes");
    out.select.tension = has("tension");
    out.select.energy = has("energy");
    out.select.forces = has("forces");
    out.select.stats = has("stats");
  }
  if (s.has("formats")) {
    const auto formats = s.string_list("formats", {"csv", "vtk"});
    out.select.csv = std::find(formats.begin(), formats.end(), "csv") != formats.end();
    out.select.vtk = std::find(formats.begin(), formats.end(), "vtk") != formats.end();
  }
  out.select.vtk_ascii = s.choice("vtk_encoding", {"binary", "ascii"}, "binary") == "ascii";
  if (out.select.vtk && !out.select.nodes)
    s.fail(s.has("fields") ? "fields" : "formats",
           fmt::format("output.formats includes \"vtk\" (the default), which draws the string from its nodes: "
                       "output.fields must include \"nodes\" (or set formats = [\"csv\"])"));
}

void parse_stop(const Section& top, Context& ctx) {
  if (!top.has("stop"))
    throw InputError(fmt::format("{}:1:1: the scene needs a [stop] section with t_end (the end time, s, > 0)",
                                 ctx.text.name()));
  Section s(subtable(top, "stop"), "stop", ctx, {"t_end", "front"});
  if (!s.has("t_end")) s.missing("t_end", "the end time, s, > 0");
  ctx.spec.stop.t_end = *s.positive("t_end");
  const auto tables = table_array(s, "front", "stop event");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    Section f(*tables[k], fmt::format("stop.front[{}]", k), ctx, {"front", "s0"});
    if (!f.has("front")) f.missing("front", "which front: fold, heap_start, heap_end, edge<k> (an [[effects.edge]]) or touchdown<k> (an [[effects.surface]] with f)");
    if (!f.has("s0")) f.missing("s0", "m, stop when that front reaches this material coordinate");
    // Edges and pegs are fronts that move along the material too: "edge<k>", k the index of an [[effects.edge]]
    // (parsed before [stop]), as the fronts are named in the run's summary.
    std::vector<std::string> fronts = {"fold", "heap_start", "heap_end"};
    for (std::size_t e = 0; e < ctx.spec.effects.edges.size(); ++e) fronts.push_back(fmt::format("edge{}", e));
    // A touchdown front: "touchdown<k>", k the index of its [[effects.surface]] (with f).
    for (std::size_t e = 0; e < ctx.spec.effects.surfaces.size(); ++e)
      if (ctx.spec.effects.surfaces[e].f) fronts.push_back(fmt::format("touchdown{}", e));
    ctx.spec.stop.fronts.push_back({f.choice("front", fronts, ""), *f.number("s0")});
  }
}

void parse_model(const Section& top, Context& ctx) {
  ctx.spec.model = top.choice("model", {"string", "reduced"}, "string");
}

}  // namespace chainsim::scene_parse
