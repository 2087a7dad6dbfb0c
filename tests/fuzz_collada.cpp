// libFuzzer target: scene text -> parse_collada -> make_render_scene (tiny render parameters) and
// one autofocus ray; never renders (fuzz_scene.h). Built only in build-fuzz by scripts/fuzz.sh
// (clang, -fsanitize=fuzzer,address,undefined). A loader error must be a SceneError; anything
// else escaping, a sanitizer report, a timeout or an out-of-memory is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "collada.h"
#include "fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  pt::SceneDesc desc;
  try {
    desc = pt::parse_collada(text, "fuzz.dae", fuzz::scene_limits());
  } catch (const pt::SceneError&) {
    return 0;  // a located load error: the expected outcome for most inputs
  }
  return fuzz::build_and_probe(desc, size);
}
