// glTF 2.0 (.gltf, .glb) -> SceneDesc, with every error located by file and JSON path
// ("scene.gltf: /meshes/3/primitives/0/indices: ..."). How materials, lights and cameras map onto
// ours, and what is approximated: docs/gltf.md. Most callers want load_scene (scene_file.h).
#pragma once

#include <string>

#include "scene.h"
#include "load_limits.h"

namespace pt {

// Parses a glTF held in memory: JSON text, or with `binary` a .glb. External buffers and images
// are read from `base_dir` only (never outside it); an empty base_dir refuses them.
SceneDesc parse_gltf(const std::string& bytes, const std::string& name, bool binary, const LoadLimits& limits = {},
                     const std::string& base_dir = "");

// KHR_lights_punctual gives point and spot intensity in candela (lm/sr) and directional
// illuminance in lux (lm/m^2); our lights are radiometric (W/sr, W/m^2; radiance in W/(sr m^2), the
// unit emissive materials are read in). The conversion divides by the maximum luminous efficacy,
// 683 lm/W (CIE; as Blender's glTF importer does: PBR_WATTS_TO_LUMENS), the colour multiplying.
constexpr double kLumensPerWatt = 683.0;
inline Vec3 radiometric_from_photometric(Vec3 color, double lumens_per_unit) {
  return color * float(lumens_per_unit / kLumensPerWatt);
}

}  // namespace pt
