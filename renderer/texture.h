// Colour textures at shading time: wrap, filter, sRGB decode (textures are stored as the file's
// 8-bit sRGB texels, SceneDesc's TextureDesc).
#pragma once

#include <cstdint>

#include "math.h"
#include "scene.h"

namespace pt {

// The sRGB transfer function's inverse (IEC 61966-2-1), for an 8-bit code.
float srgb8_to_linear(uint8_t code);

// The 8-bit sRGB code of a linear value in [0, 1] (clamped), rounded to nearest.
uint8_t linear_to_srgb8(float v);

// Linear RGB of the texture at uv (sRGB decoded for colour textures), wrapped as its sampler
// says; bilinear unless `nearest`.
Vec3 eval_texture(const TextureDesc& texture, Vec2 uv);

// The texture's alpha at uv, filtered as eval_texture filters colour; 1 where it has none.
float eval_texture_alpha(const TextureDesc& texture, Vec2 uv);

// The mean linear colour of a texture: what materials without per-hit texturing use of it.
Vec3 texture_mean(const TextureDesc& texture);

}  // namespace pt
