// glTF materials -> ours: every glTF material is the pbr material (pbr.h), its factors read here
// and its textures kept for the hits to read (textured_material): base colour, metal / roughness,
// emission, normal map, transmission, each through its TEXCOORD set and KHR_texture_transform.
// The mapping and what is left out: docs/gltf.md.
#include <cmath>

#include "ggx.h"
#include "gltf_reader.h"

namespace pt::gltf_detail {

namespace {

// The extension object `name` of a material, or nullptr.
const tinygltf::Value* extension(const tinygltf::ExtensionMap& ext, const char* name) {
  auto it = ext.find(name);
  return it == ext.end() || !it->second.IsObject() ? nullptr : &it->second;
}

double number(const tinygltf::Value* o, const char* key, double def) {
  if (!o || !o->Has(key) || !o->Get(key).IsNumber()) return def;
  return o->Get(key).GetNumberAsDouble();
}

Vec3 color3(const tinygltf::Value* o, const char* key, Vec3 def) {
  if (!o || !o->Has(key)) return def;
  const tinygltf::Value& a = o->Get(key);
  if (!a.IsArray() || a.ArrayLen() != 3) return def;
  Vec3 c;
  for (int i = 0; i < 3; ++i) c[i] = float(a.Get(i).GetNumberAsDouble());
  return c;
}

Vec3 factor3(const std::vector<double>& f, Vec3 def) {
  return f.size() >= 3 ? Vec3(float(f[0]), float(f[1]), float(f[2])) : def;
}

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

const TextureDesc* MaterialMaker::image_of(int texture, const std::string& path) {
  const tinygltf::Texture& t = m_model.textures[size_t(texture)];
  if (t.source < 0) {
    m_ctx.warn("texture without source", path, "texture " + std::to_string(texture) +
                                                   " has no source image (only an extension's): it is ignored");
    return nullptr;
  }
  if (!m_images.ok[size_t(t.source)])
    m_ctx.fail(path, "image " + std::to_string(t.source) + " of texture " + std::to_string(texture) + " could not be read");
  return &m_images.images[size_t(t.source)];
}

int MaterialMaker::texture_for(int texture, bool srgb, const std::string& path) {
  std::vector<int>& cache = m_texture_of[srgb ? 1 : 0];
  if (cache.empty()) cache.assign(m_model.textures.size(), -2);
  int& slot = cache[size_t(texture)];
  if (slot != -2) return slot;
  const TextureDesc* image = image_of(texture, path);
  if (!image) return slot = -1;
  TextureDesc t = *image;
  t.srgb = srgb;
  const tinygltf::Texture& gt = m_model.textures[size_t(texture)];
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

TextureRef MaterialMaker::texture_ref(int texture, int tex_coord, const tinygltf::ExtensionMap& ext, bool srgb,
                                      const std::string& path) {
  TextureRef r;
  if (texture < 0) return r;
  r.texture = texture_for(texture, srgb, path);
  if (r.texture < 0) return r;
  r.set = tex_coord;
  // KHR_texture_transform: uv' = T R S uv, R rotating counter-clockwise (the extension's GLSL).
  if (const tinygltf::Value* t = extension(ext, "KHR_texture_transform")) {
    const std::string at = path + "/extensions/KHR_texture_transform";
    double off[2] = {0, 0}, scale[2] = {1, 1};
    for (int i = 0; i < 2; ++i) {
      if (t->Has("offset") && t->Get("offset").ArrayLen() == 2) off[i] = t->Get("offset").Get(i).GetNumberAsDouble();
      if (t->Has("scale") && t->Get("scale").ArrayLen() == 2) scale[i] = t->Get("scale").Get(i).GetNumberAsDouble();
    }
    const double rot = number(t, "rotation", 0), c = std::cos(rot), s = std::sin(rot);
    const double m[6] = {c * scale[0], -s * scale[1], off[0], s * scale[0], c * scale[1], off[1]};
    for (int i = 0; i < 6; ++i) {
      if (!std::isfinite(m[i])) m_ctx.fail(at, "is not finite (offset, rotation or scale)");
      r.m[i] = float(m[i]);
    }
    r.transformed = true;
    if (t->Has("texCoord")) r.set = int(number(t, "texCoord", tex_coord));
  }
  if (r.set > 1) {
    m_ctx.warn("texCoord " + std::to_string(r.set), path + "/texCoord",
               "TEXCOORD_" + std::to_string(r.set) + " is not read (sets 0 and 1 are): TEXCOORD_0 is used");
    r.set = 0;
  }
  return r;
}

TextureRef MaterialMaker::texture_ref(const tinygltf::TextureInfo& info, bool srgb, const std::string& path) {
  return texture_ref(info.index, info.texCoord, info.extensions, srgb, path);
}

TextureRef MaterialMaker::extension_texture(const tinygltf::Value& ext, const char* key, bool srgb, const std::string& path) {
  if (!ext.Has(key)) return TextureRef();
  const tinygltf::Value& info = ext.Get(key);
  tinygltf::ExtensionMap extensions;  // the info's own, for KHR_texture_transform
  if (info.Has("extensions") && info.Get("extensions").IsObject())
    for (const std::string& name : info.Get("extensions").Keys()) extensions[name] = info.Get("extensions").Get(name);
  return texture_ref(int(number(&info, "index", -1)), int(number(&info, "texCoord", 0)), extensions, srgb, path + "/" + key);
}

Material MaterialMaker::make(int index, bool vertex_color, const std::string& path) {
  static const tinygltf::Material kDefault;  // glTF's default material: white, metallic 1, roughness 1
  const tinygltf::Material& g = index >= 0 ? m_model.materials[size_t(index)] : kDefault;
  const std::string at = index >= 0 ? "/materials/" + std::to_string(index) : path;
  const std::string pbr_at = at + "/pbrMetallicRoughness";
  const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
  Material m;
  m.name = !g.name.empty() ? g.name : index >= 0 ? "material " + std::to_string(index) : "default";
  m.type = MaterialType::pbr;
  PbrParams& p = m.pbr;
  p.base = factor3(pbr.baseColorFactor, Vec3(1.0f));
  p.metallic = float(pbr.metallicFactor);
  p.roughness = float(pbr.roughnessFactor);
  p.vertex_color = vertex_color;
  p.double_sided = g.doubleSided;
  p.base_tex = texture_ref(pbr.baseColorTexture, true, pbr_at + "/baseColorTexture");
  p.metal_rough_tex = texture_ref(pbr.metallicRoughnessTexture, false, pbr_at + "/metallicRoughnessTexture");
  if (g.normalTexture.index >= 0) {
    p.normal_tex = texture_ref(g.normalTexture.index, g.normalTexture.texCoord, g.normalTexture.extensions, false,
                               at + "/normalTexture");
    p.normal_scale = float(g.normalTexture.scale);
  }
  p.alpha = pbr.baseColorFactor.size() >= 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
  if (g.alphaMode == "MASK") {
    p.alpha_mode = AlphaMode::mask;
    p.alpha_cutoff = float(g.alphaCutoff);
    if (p.alpha_cutoff > 1)
      m_ctx.warn("alphaCutoff", at + "/alphaCutoff", "alphaCutoff " + std::to_string(p.alpha_cutoff) +
                                                         " is above 1: the whole surface is cut out");
  } else if (g.alphaMode == "BLEND") {
    p.alpha_mode = AlphaMode::blend;
  } else if (g.alphaMode != "OPAQUE" && !g.alphaMode.empty()) {
    m_ctx.warn("alphaMode", at + "/alphaMode", "alphaMode " + clip(g.alphaMode) + " is none of OPAQUE, MASK and BLEND: "
                                               "the surface renders opaque");
  }
  // Alpha that is 1 everywhere changes nothing: the surface stays opaque (and untested).
  const bool alpha_texture = p.base_tex.used() && !m_desc.textures[size_t(p.base_tex.texture)].alpha.empty();
  const bool constant_alpha = !alpha_texture && !vertex_color;
  if ((p.alpha_mode == AlphaMode::blend && p.alpha >= 1 && constant_alpha) ||
      (p.alpha_mode == AlphaMode::mask && p.alpha >= p.alpha_cutoff && constant_alpha))
    p.alpha_mode = AlphaMode::opaque;

  // Emission: emissiveFactor x KHR_materials_emissive_strength (x the emissive texture per hit),
  // in our radiance units (docs/gltf.md).
  p.emissive = factor3(g.emissiveFactor, Vec3(0.0f)) *
               float(number(extension(g.extensions, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0));
  if (!is_black(p.emissive))
    p.emissive_tex = texture_ref(g.emissiveTexture, true, at + "/emissiveTexture");

  const std::string ext_at = at + "/extensions/";
  const double ior = number(extension(g.extensions, "KHR_materials_ior"), "ior", 1.5);
  p.ior = float(ior >= 1 ? ior : 1.5);  // 0 (a perfect reflector) is read as glTF's default
  if (const tinygltf::Value* t = extension(g.extensions, "KHR_materials_transmission")) {
    p.transmission = float(number(t, "transmissionFactor", 0));
    if (p.transmission > 0)
      p.transmission_tex = extension_texture(*t, "transmissionTexture", false, ext_at + "KHR_materials_transmission");
  }
  if (const tinygltf::Value* s = extension(g.extensions, "KHR_materials_specular")) {
    p.specular = float(number(s, "specularFactor", 1));
    p.specular_color = color3(s, "specularColorFactor", Vec3(1.0f));
    p.specular_tex = extension_texture(*s, "specularTexture", false, ext_at + "KHR_materials_specular");  // alpha
    p.specular_color_tex = extension_texture(*s, "specularColorTexture", true, ext_at + "KHR_materials_specular");
  }
  if (const tinygltf::Value* c = extension(g.extensions, "KHR_materials_clearcoat")) {
    const std::string c_at = ext_at + "KHR_materials_clearcoat";
    p.clearcoat = float(number(c, "clearcoatFactor", 0));
    p.clearcoat_roughness = float(number(c, "clearcoatRoughnessFactor", 0));
    if (p.clearcoat > 0) {
      p.clearcoat_tex = extension_texture(*c, "clearcoatTexture", false, c_at);  // red
      p.clearcoat_roughness_tex = extension_texture(*c, "clearcoatRoughnessTexture", false, c_at);  // green
      p.clearcoat_normal_tex = extension_texture(*c, "clearcoatNormalTexture", false, c_at);
      if (p.clearcoat_normal_tex.used()) {
        p.clearcoat_normal_scale = float(number(&c->Get("clearcoatNormalTexture"), "scale", 1));
        if (p.normal_tex.used() && p.clearcoat_normal_tex.set != p.normal_tex.set)
          m_ctx.warn("clearcoat normal map", c_at + "/clearcoatNormalTexture",
                     "reads another uv set than normalTexture: the tangents of normalTexture's set are used");
      }
    }
  }
  if (const tinygltf::Value* s = extension(g.extensions, "KHR_materials_sheen")) {
    const std::string s_at = ext_at + "KHR_materials_sheen";
    p.sheen_color = color3(s, "sheenColorFactor", Vec3(0.0f));
    p.sheen_roughness = float(number(s, "sheenRoughnessFactor", 0));
    if (!is_black(p.sheen_color)) {
      p.sheen_color_tex = extension_texture(*s, "sheenColorTexture", true, s_at);
      p.sheen_roughness_tex = extension_texture(*s, "sheenRoughnessTexture", false, s_at);  // alpha
    }
  }
  // KHR_materials_volume: Beer-Lambert absorption inside the mesh, sigma = -ln(colour) / distance;
  // a thickness of 0 means a thin wall, which has no inside.
  if (const tinygltf::Value* v = extension(g.extensions, "KHR_materials_volume")) {
    const double distance = number(v, "attenuationDistance", 0);  // absent: infinite, nothing absorbed
    if (number(v, "thicknessFactor", 0) > 0 && distance > 0 && std::isfinite(distance)) {
      const Vec3 colour = color3(v, "attenuationColor", Vec3(1.0f));
      for (int i = 0; i < 3; ++i)
        p.attenuation[i] = float(-std::log(std::max(1e-6, double(colour[i]))) / distance);
    }
    if (v->Has("thicknessTexture"))
      m_ctx.warn("thickness texture", ext_at + "KHR_materials_volume/thicknessTexture",
                 "a path tracer measures the thickness the rays cross: the texture is not read");
  }
  // KHR_materials_unlit: the base colour, emitted and nothing reflected (docs/gltf.md).
  if (extension(g.extensions, "KHR_materials_unlit")) {
    p.unlit = true;
    p.emissive = p.base;  // x the base colour texture and COLOR_0 per hit (textured_material)
    p.base = Vec3(0.0f);
    p.emissive_tex = TextureRef();
    p.metal_rough_tex = p.normal_tex = TextureRef();
    p.specular = 0, p.metallic = 0, p.transmission = 0, p.clearcoat = 0, p.sheen_color = Vec3(0.0f);
  }
  // Smooth untextured glass and metal are the exact delta BSDFs: the same light as the rough lobes
  // in the limit, and the light tracer renders their caustics.
  const bool smooth_plain = ggx::alpha_of(p.roughness) <= ggx::kMinAlpha && !p.textured() && is_black(p.emissive) &&
                            p.clearcoat <= 0 && is_black(p.sheen_color) && is_black(p.attenuation);
  const Vec3 base = max(Vec3(0.0f), min(Vec3(1.0f), p.base));
  if (smooth_plain && p.transmission >= 1 && p.metallic <= 0 && p.specular == 1 && p.specular_color == Vec3(1.0f)) {
    m.type = MaterialType::glass;
    m.albedo = Vec3(1.0f);
    m.transmittance = base;
    m.ior = p.ior;
  } else if (smooth_plain && p.metallic >= 1) {
    m.type = MaterialType::mirror;
    m.albedo = base;
    m.schlick = true;
  }
  return m;
}

}  // namespace pt::gltf_detail
