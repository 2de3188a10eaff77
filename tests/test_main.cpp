// The test binary's main: Catch2's session, then the removal of this process's temporary files
// (chainsim::test::temp_path) when every test it ran passed; a failed run keeps them to look at.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "tests/unit/test_scene_support.hpp"

int main(int argc, char* argv[]) {
  const int failed = Catch::Session().run(argc, argv);
  if (failed == 0) chainsim::test::remove_temp_paths();
  return failed;
}
