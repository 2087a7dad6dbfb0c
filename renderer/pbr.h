// The glTF 2.0 metal-rough BSDF (the specification's Appendix B) as Blender's Cycles renders the
// material its importer builds (Principled BSDF): mix(dielectric, metal, metallic), the dielectric
// a GGX specular layer with the exact Fresnel term of the ior over a Lambertian base, the metal a
// GGX lobe with Schlick's Fresnel from F0 = base colour, and transmission a rough dielectric
// (Walter et al. 2007). Single-scattering GGX loses energy on rough surfaces: the reflection lobes
// are scaled back up as Turquin 2019 ("Practical multiple scattering compensation for microfacet
// models") does, and the base under the specular layer is weighted by what that layer leaves
// (1 - its directional albedo towards wo, as Cycles layers its closures). On top, in that order,
// KHR_materials_clearcoat's GGX coat (ior 1.5) and KHR_materials_sheen's microfibre sheen
// (sheen.h), each layered the same way. Lobes are sampled in proportion to their expected weight;
// the pdf is the mixture's, so MIS sees one BSDF.
// Frame conventions as materials.h: z > 0 is the outside for transmissive materials.
#pragma once

#include "materials.h"
#include "scene.h"

namespace pt {

Vec3 pbr_eval(const PbrParams& p, Vec3 wo, Vec3 wi);
float pbr_pdf(const PbrParams& p, Vec3 wo, Vec3 wi);
bool pbr_sample(const PbrParams& p, Vec3 wo, float u_lobe, Vec2 u, BsdfSample& s);

// The lobes' selection probabilities at wo, for tests.
struct PbrLobeWeights {
  float metal = 0, specular = 0, diffuse = 0, transmission = 0, coat = 0, sheen = 0;
};
PbrLobeWeights pbr_lobe_weights(const PbrParams& p, Vec3 wo);

}  // namespace pt
