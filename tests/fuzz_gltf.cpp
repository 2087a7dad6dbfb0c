// libFuzzer target: glTF bytes (.gltf JSON, or a .glb by its magic) -> parse_scene ->
// make_render_scene (tiny render parameters) and one autofocus ray; never renders (fuzz_scene.h).
// Built only in build-fuzz by scripts/fuzz.sh, as fuzz_collada. A loader error must be a
// SceneError; anything else escaping, a sanitizer report, a timeout or an out-of-memory is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_scene.h"
#include "scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  pt::SceneDesc desc;
  try {
    desc = pt::parse_scene(bytes, "fuzz.gltf", fuzz::scene_limits());  // no folder: external files are refused
  } catch (const pt::SceneError&) {
    return 0;  // a located load error: the expected outcome for most inputs
  }
  return fuzz::build_and_probe(desc, size);
}
