// libFuzzer target: TOML text -> resolved scene. Input: the scene text, then optional NUL-separated `--set`
// assignments. A SceneError is a normal rejection; anything else (another exception, a sanitizer report, an
// abort) is a bug. An accepted scene must print as TOML that parses back to the same scene.
//
//   tests/fuzz/run.sh                                  # builds with clang and runs every target
//   build-fuzz/tests/fuzz/fuzz_scene tests/fuzz/corpus_scene -max_total_time=60
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "dem/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = input.find('\0');
  const std::string_view toml_text = input.substr(0, nul);
  try {
    rbdem::Scene scene = rbdem::parse_scene(toml_text, "fuzz.toml");
    std::string_view rest = nul == std::string_view::npos ? std::string_view{} : input.substr(nul + 1);
    while (!rest.empty()) {
      const std::size_t end = rest.find('\0');
      rbdem::apply_override(scene, rest.substr(0, end));
      rest = end == std::string_view::npos ? std::string_view{} : rest.substr(end + 1);
    }
    rbdem::validate(scene);
    const std::string printed = rbdem::to_toml(scene);
    const rbdem::Scene back = rbdem::parse_scene(printed, "printed");
    if (rbdem::to_toml(back) != printed) std::abort();  // the printed scene must round-trip exactly
    (void)rbdem::scene_json(scene).dump();
    rbdem::check_plausible(scene);
  } catch (const rbdem::SceneError&) {
    // a rejection with a message: the expected outcome for bad input
  }
  return 0;
}
