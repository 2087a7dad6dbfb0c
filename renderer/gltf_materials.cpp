// glTF materials -> ours: pbrMetallicRoughness onto the nearer of our BSDFs (diffuse, the
// microfacet conductor, the mirror), transmission onto glass, emission onto emitters; base colour
// textures per hit on diffuse materials, their mean elsewhere. The mapping and what it
// approximates: docs/gltf.md.
#include <cmath>

#include "gltf_reader.h"
#include "texture.h"

namespace pt {

void conductor_from_reflectance(Vec3 r, Vec3& eta, Vec3& k) {
  for (int c = 0; c < 3; ++c) {
    double f = std::min(std::max(double(r[c]), 0.0), 0.999), g = f;  // edge tint = reflectance
    double sf = std::sqrt(f);
    double n_min = (1 - f) / (1 + f), n_max = (1 + sf) / (1 - sf);
    double n = g * n_min + (1 - g) * n_max;  // Gulbrandsen 2014, eq. 3
    double k2 = ((n + 1) * (n + 1) * f - (n - 1) * (n - 1)) / (1 - f);  // eq. 4
    eta[c] = float(n);
    k[c] = float(std::sqrt(std::max(k2, 0.0)));
  }
}

}  // namespace pt

namespace pt::gltf_detail {

namespace {

// The value of a number in a material extension, or `def`.
double extension_number(const tinygltf::ExtensionMap& ext, const char* name, const char* key, double def) {
  auto it = ext.find(name);
  if (it == ext.end() || !it->second.Has(key) || !it->second.Get(key).IsNumber()) return def;
  return it->second.Get(key).GetNumberAsDouble();
}

Vec3 lerp(Vec3 a, Vec3 b, float t) { return a * (1 - t) + b * t; }

}  // namespace

int MaterialMaker::material(int index, bool vertex_color, const std::string& path) {
  std::vector<int>& made = m_made[vertex_color ? 1 : 0];
  if (made.empty()) made.assign(m_model.materials.size() + 1, -1);
  int& slot = made[size_t(index + 1)];
  if (slot < 0) {
    Material m = make(index, vertex_color, path);
    slot = int(m_desc.materials.size());
    m_desc.materials.push_back(std::move(m));
  }
  return slot;
}

int MaterialMaker::texcoord_set(int index) {
  if (index < 0) return 0;
  return m_model.materials[size_t(index)].pbrMetallicRoughness.baseColorTexture.texCoord;
}

const TextureDesc* MaterialMaker::image_of(const tinygltf::TextureInfo& info, const std::string& path) {
  const tinygltf::Texture& t = m_model.textures[size_t(info.index)];
  if (t.source < 0) {
    m_ctx.warn("texture without source", path, "texture " + std::to_string(info.index) +
                                                   " has no source image (only an extension's): it is ignored");
    return nullptr;
  }
  if (!m_images.ok[size_t(t.source)])
    m_ctx.fail(path, "image " + std::to_string(t.source) + " of texture " + std::to_string(info.index) + " could not be read");
  return &m_images.images[size_t(t.source)];
}

int MaterialMaker::texture_for(const tinygltf::TextureInfo& info, const std::string& path) {
  if (m_texture_of.empty()) m_texture_of.assign(m_model.textures.size(), -2);
  int& slot = m_texture_of[size_t(info.index)];
  if (slot != -2) return slot;
  const TextureDesc* image = image_of(info, path);
  if (!image) return slot = -1;
  TextureDesc t = *image;
  const tinygltf::Texture& gt = m_model.textures[size_t(info.index)];
  if (gt.sampler >= 0) {
    const tinygltf::Sampler& s = m_model.samplers[size_t(gt.sampler)];
    auto wrap = [](int w) {
      return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE ? TextureWrap::clamp
             : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TextureWrap::mirror
                                                          : TextureWrap::repeat;
    };
    t.wrap_s = wrap(s.wrapS);
    t.wrap_t = wrap(s.wrapT);
    t.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
    if (s.minFilter >= TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST)
      m_ctx.warn("mipmaps", "/samplers/" + std::to_string(gt.sampler) + "/minFilter",
                 "minFilter " + std::to_string(s.minFilter) + " asks for mipmaps: textures are filtered without them "
                 "(the pixel's samples average what they cover)");
  }
  slot = int(m_desc.textures.size());
  m_desc.textures.push_back(std::move(t));
  return slot;
}

Material MaterialMaker::make(int index, bool vertex_color, const std::string& path) {
  static const tinygltf::Material kDefault;  // glTF's default material: white, metallic 1, roughness 1
  const tinygltf::Material& g = index >= 0 ? m_model.materials[size_t(index)] : kDefault;
  const std::string at = index >= 0 ? "/materials/" + std::to_string(index) : path;
  const std::string pbr_at = at + "/pbrMetallicRoughness";
  const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
  Material m;
  m.name = !g.name.empty() ? g.name : index >= 0 ? "material " + std::to_string(index) : "default";

  Vec3 base(1.0f);
  if (pbr.baseColorFactor.size() >= 3) base = Vec3(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]), float(pbr.baseColorFactor[2]));
  float metallic = float(pbr.metallicFactor), roughness = float(pbr.roughnessFactor);
  if (pbr.metallicRoughnessTexture.index >= 0) {
    // Linear data: roughness in G, metalness in B (glTF 2.0, 3.9.2); their means scale the factors.
    if (const TextureDesc* t = image_of(pbr.metallicRoughnessTexture, pbr_at + "/metallicRoughnessTexture")) {
      double sum_g = 0, sum_b = 0;
      const size_t n = size_t(t->width) * size_t(t->height);
      for (size_t i = 0; i < n; ++i) sum_g += t->texels[3 * i + 1], sum_b += t->texels[3 * i + 2];
      roughness *= float(sum_g / (255.0 * double(n)));
      metallic *= float(sum_b / (255.0 * double(n)));
      m_ctx.warn("metallicRoughnessTexture", pbr_at + "/metallicRoughnessTexture",
                 "metal / roughness textures are not read per hit: their mean over the image scales the factors");
    }
  }
  if (g.alphaMode != "OPAQUE" && !g.alphaMode.empty())
    m_ctx.warn("alphaMode", at + "/alphaMode", "alphaMode " + clip(g.alphaMode) + " is not supported: surfaces render opaque");
  if (g.normalTexture.index >= 0) m_ctx.warn("normalTexture", at + "/normalTexture", "normal maps are ignored");
  auto transmission_ext = g.extensions.find("KHR_materials_transmission");
  if (transmission_ext != g.extensions.end() && transmission_ext->second.Has("transmissionTexture"))
    m_ctx.warn("transmissionTexture", at + "/extensions/KHR_materials_transmission/transmissionTexture",
               "transmission textures are ignored: the factor decides");
  if (g.occlusionTexture.index >= 0)
    m_ctx.warn("occlusionTexture", at + "/occlusionTexture", "occlusion textures are ignored (the path tracer finds occlusion)");

  // Emission: emissiveFactor x KHR_materials_emissive_strength (x the emissive texture's mean), in
  // our radiance units; our emitters reflect nothing (docs/gltf.md).
  Vec3 emissive(0.0f);
  if (g.emissiveFactor.size() == 3) emissive = Vec3(float(g.emissiveFactor[0]), float(g.emissiveFactor[1]), float(g.emissiveFactor[2]));
  emissive = emissive * float(extension_number(g.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0));
  if (g.emissiveTexture.index >= 0 && !is_black(emissive))
    if (const TextureDesc* t = image_of(g.emissiveTexture, at + "/emissiveTexture")) {
      emissive = emissive * texture_mean(*t);
      m_ctx.warn("emissiveTexture", at + "/emissiveTexture", "emissive textures are not read per hit: their mean colour is used");
    }
  if (!is_black(emissive)) {
    m.type = MaterialType::emission;
    m.radiance = emissive;
    return m;
  }

  // What a material that is not diffuse takes of a base colour texture: its mean colour.
  const bool textured = pbr.baseColorTexture.index >= 0;
  auto base_mean = [&](const char* what) {
    if (!textured) return base;
    const TextureDesc* t = image_of(pbr.baseColorTexture, pbr_at + "/baseColorTexture");
    if (!t) return base;
    m_ctx.warn(std::string("mean texture ") + what, pbr_at + "/baseColorTexture",
               std::string("base colour textures of ") + what + " materials are not read per hit: their mean colour is used");
    return base * texture_mean(*t);
  };
  if (vertex_color && (metallic >= 0.5f || extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0) >= 0.5))
    m_ctx.warn("vertex colours", path, "vertex colours (COLOR_0) colour diffuse materials only: ignored here");

  // Transmission onto glass: Fresnel reflection and refraction at the KHR_materials_ior index, the
  // base colour tinting what passes (KHR_materials_transmission); smooth whatever the roughness.
  const double transmission = extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0);
  if (transmission >= 0.5) {
    double ior = extension_number(g.extensions, "KHR_materials_ior", "ior", 1.5);
    m.type = MaterialType::glass;
    m.albedo = Vec3(1.0f);
    m.transmittance = base_mean("glass");
    m.ior = float(ior >= 1 ? ior : 1.5);
    if (roughness > 0.05f)
      m_ctx.warn("rough glass", at, "rough transmission is rendered smooth (our glass has no roughness)");
    return m;
  }
  if (transmission > 0)
    m_ctx.warn("partial transmission", at, "transmissionFactor below 0.5 is rendered opaque");

  // Metals: the conductor whose reflectance head on is F0 = lerp(0.04, base, metallic) (the glTF
  // BRDF's, appendix B.3.5), Beckmann alpha = roughness^2; a smooth one is our mirror.
  if (metallic >= 0.5f) {
    const Vec3 f0 = lerp(Vec3(0.04f), base_mean("metallic"), metallic);
    const float alpha = roughness * roughness;
    if (alpha < 1e-3f) {
      m.type = MaterialType::mirror;
      m.albedo = f0;
    } else {
      m.type = MaterialType::microfacet;
      m.alpha = alpha;
      conductor_from_reflectance(f0, m.eta, m.k);
    }
    if (metallic < 1) m_ctx.warn("partly metallic", pbr_at + "/metallicFactor", "metallic between 0.5 and 1 is rendered as a metal");
    return m;
  }
  // Dielectrics: the diffuse lobe with the glTF BRDF's weight (1 - metallic) base; its specular
  // layer is not rendered.
  if (metallic > 0) m_ctx.warn("partly dielectric", pbr_at + "/metallicFactor", "metallic below 0.5 is rendered as a diffuse surface");
  m.type = MaterialType::diffuse;
  m.albedo = base * (1 - metallic);
  if (textured) m.texture = texture_for(pbr.baseColorTexture, pbr_at + "/baseColorTexture");
  m.vertex_color = vertex_color;
  return m;
}

}  // namespace pt::gltf_detail
