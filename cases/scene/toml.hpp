#pragma once
/// @file toml.hpp
/// toml++, the scene files' parser, as the scene code uses it: compiled from its headers here, with
/// std::from_chars for floats. Debian's shared library reads every float through a std::stringstream
/// (it is built with TOML_FLOAT_CHARCONV=0): about 14,000 instructions a number, 110 M of the 141 M
/// that parsing a scene of 8,002 numbers took (docs/stability.md, "Outputs, judged before the run").
/// Both conversions round correctly, so a scene reads as the same doubles. Include toml++ through this
/// header only, so that every copy of its inline code has the same configuration.
/// The package's CMake target defines TOML_HEADER_ONLY=0 and TOML_SHARED_LIB=1 (its shared library);
/// the definitions below replace them. Its code compiled here is what the scene code calls (an
/// executable's own definitions come before a shared library's).
/// The sanitized build (CHAINSIM_SANITIZE) defines CHAINSIM_TOML_FROM_LIBRARY and keeps the library:
/// toml++'s inline formatter has undefined behaviour that UBSan would report (CMakeLists.txt).
#ifndef CHAINSIM_TOML_FROM_LIBRARY
#undef TOML_HEADER_ONLY
#undef TOML_SHARED_LIB
#undef TOML_FLOAT_CHARCONV
#define TOML_HEADER_ONLY 1
#define TOML_SHARED_LIB 0
#define TOML_FLOAT_CHARCONV 1
#endif
#include <toml++/toml.h>
