// libFuzzer target: scene text -> parse_scene_text -> the model builders (see scene_input.hpp).
// Built with -DCHAINSIM_FUZZ=ON (clang); .ci/run runs it for a bounded time on a corpus seeded with
// cases/scenes/*.toml. An input that crashes becomes a file in tests/fuzz/regressions/.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tests/fuzz/scene_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  chainsim::fuzz::check_scene_text(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
