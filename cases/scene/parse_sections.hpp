#pragma once
/// @file parse_sections.hpp
/// One parse function per section of a scene (internal to cases/scene/), each filling its part of
/// ctx.spec from the checked top-level table `top`:
///   parse_string.cpp   [string], [shape], [velocity], [ends]
///   parse_effects.cpp  [effects.*]: gravity, drag, heap, fold, plane
///   parse_run.cpp      [solver], [output], [stop], model
/// parse_scene.cpp reads the file and calls them in this order.
#include "cases/scene/checked_table.hpp"

namespace chainsim::scene_parse {

void parse_model(const Section& top, Context& ctx);
void parse_string(const Section& top, Context& ctx);
void parse_shape(const Section& top, Context& ctx);
void parse_velocity(const Section& top, Context& ctx);
void parse_ends(const Section& top, Context& ctx);
void parse_effects(const Section& top, Context& ctx);
void parse_solver(const Section& top, Context& ctx);
void parse_output(const Section& top, Context& ctx);
void parse_stop(const Section& top, Context& ctx);

}  // namespace chainsim::scene_parse
