// The scene fuzzer's input path (tests/fuzz/scene_input.hpp) on the example scenes, which it must
// accept, and on every input kept in tests/fuzz/regressions/ (inputs that once crashed or that probe
// edge values): each must be accepted or refused with an InputError, never crash or throw anything
// else. The sanitizer build of this suite (.ci/run) also checks them for memory errors and UB.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <catch2/catch.hpp>

#include "tests/fuzz/scene_input.hpp"

namespace fs = std::filesystem;

namespace {
std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}
}  // namespace

TEST_CASE("the example scenes pass the fuzzer's input path", "[hard][fuzz]") {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes")) {
    INFO(entry.path());
    CHECK(chainsim::fuzz::check_scene_text(read(entry.path())).empty());
    ++n;
  }
  CHECK(n >= 10);
}

TEST_CASE("fuzzer regression inputs are accepted or refused with a message", "[hard][fuzz]") {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(CHAINSIM_SOURCE_DIR) / "tests" / "fuzz" / "regressions")) {
    INFO(entry.path());
    std::string refusal;
    REQUIRE_NOTHROW(refusal = chainsim::fuzz::check_scene_text(read(entry.path())));
    if (!refusal.empty()) CHECK_THAT(refusal, Catch::Matchers::Contains("fuzz.toml:"));  // located
    ++n;
  }
  CHECK(n >= 3);
}
