// libFuzzer target: glTF bytes (.gltf JSON, or a .glb by its magic) -> parse_scene ->
// make_render_scene (tiny render parameters) and one autofocus ray; never renders. Built only in
// build-fuzz by scripts/fuzz.sh, as fuzz_collada. A loader error must be a SceneError; anything
// else escaping, a sanitizer report, a timeout or an out-of-memory is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "scene_file.h"
#include "session.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Smaller than the defaults so each input stays fast; the limit checks themselves are exercised.
  static const pt::LoadLimits limits = [] {
    pt::LoadLimits l;
    l.max_file_bytes = size_t(4) << 20;
    l.max_triangles = 200'000;
    l.max_nodes = 20'000;
    l.max_values = 2'000'000;
    l.max_json_values = 200'000;
    l.max_texture_pixels = 1 << 20;
    l.max_texture_bytes = size_t(16) << 20;
    return l;
  }();
  std::string bytes(reinterpret_cast<const char*>(data), size);
  pt::SceneDesc desc;
  try {
    desc = pt::parse_scene(bytes, "fuzz.gltf", limits);  // no folder: external files are refused
  } catch (const pt::SceneError&) {
    return 0;  // a located load error: the expected outcome for most inputs
  }
  pt::RenderParams params;
  params.width = 8;
  params.height = 6;
  params.spp = 1;
  params.threads = 1;
  params.default_light = size % 2 == 0;
  std::unique_ptr<pt::RenderScene> scene;
  try {
    scene = pt::make_render_scene(desc, params);
  } catch (const std::runtime_error&) {
    return 0;  // a build failure (Embree) is reported, not a crash
  }
  pt::autofocus_distance(*scene, 0.5f, 0.5f);
  return 0;
}
