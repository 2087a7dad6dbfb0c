// The table of render options (options.h) and its small helpers.
#include "options.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace pt {

namespace {

#define PT_FIELD(expr) \
  [](const RenderParams& p, const RunLimits& l) { (void)p; (void)l; return double(expr); }, \
  [](RenderParams& p, RunLimits& l, double v) { (void)p; (void)l; expr = decltype(expr)(v); }

constexpr double kMaxSeed = 9007199254740992.0;  // 2^53: every seed a JSON number carries exactly

const std::vector<RenderOption> kOptions = {
    {"max_depth", "-m", OptionType::integer, 0, 1e6, 1, 5,
     "maximum ray depth: 0 = emitters only, 1 = direct light, each further bounce one more",
     "pathtracer:max_depth", PT_FIELD(p.max_depth)},
    {"aperture", "-b", OptionType::real, 0, 1e6, 0, 0, "thin-lens lens radius (the course's aperture; 0 = pinhole)",
     "pathtracer:lens_radius", PT_FIELD(p.lens_radius)},
    {"focal_distance", "-d", OptionType::real, 0, 1e12, kCourseFocalDistance, kCourseFocalDistance,
     "distance of the plane in focus along the view axis", "pathtracer:focal_distance", PT_FIELD(p.focal_distance)},
    {"spp", "-s", OptionType::integer, 1, 1 << 24, 1, 64, "camera rays (samples) per pixel", "pathtracer:spp",
     PT_FIELD(p.spp)},
    {"light_samples", "-l", OptionType::integer, 1, 65536, 1, 1,
     "samples per area, environment or ambient light at each vertex", "pathtracer:light_samples",
     PT_FIELD(p.light_samples)},
    {"width", "-r", OptionType::integer, 1, 16384, 800, 480, "image width in pixels", "pathtracer:width",
     PT_FIELD(p.width)},
    {"height", "-r", OptionType::integer, 1, 16384, 600, 360, "image height in pixels", "pathtracer:height",
     PT_FIELD(p.height)},
    {"seed", "--seed", OptionType::integer, 0, kMaxSeed, 0, 0, "random seed: the same seed, the same image",
     "pathtracer:seed", PT_FIELD(p.seed)},
    {"adaptive", "--no-adaptive", OptionType::boolean, 0, 1, 1, 1,
     "adaptive sampling: a pixel stops once its confidence interval is within the tolerance",
     "pathtracer:adaptive", PT_FIELD(p.adaptive)},
    {"adaptive_batch", "-a", OptionType::integer, 1, 65536, 32, 32, "samples between two adaptive stop tests",
     "pathtracer:adaptive_batch", PT_FIELD(p.adaptive_batch)},
    {"adaptive_tolerance", "-a", OptionType::real, 0, 1, 0.05, 0.05,
     "adaptive stop: the 95% interval within this fraction of the pixel's mean", "pathtracer:adaptive_tolerance",
     PT_FIELD(p.adaptive_tolerance)},
    {"hemisphere", "-H", OptionType::boolean, 0, 1, 0, 0,
     "uniform hemisphere sampling for direct light instead of light sampling", "pathtracer:hemisphere",
     PT_FIELD(p.hemisphere)},
    {"file_camera", "--file-camera", OptionType::boolean, 0, 1, 0, 0,
     "the scene's camera as authored instead of the course's framing", "pathtracer:file_camera",
     PT_FIELD(p.file_camera)},
    {"keep_fov", "--keep-fov", OptionType::boolean, 0, 1, 0, 0,
     "the size scales the course's 800x600 view instead of cropping it", "pathtracer:keep_fov",
     PT_FIELD(p.keep_fov)},
    {"frame_scene", "--frame-scene", OptionType::boolean, 0, 1, 0, 0,
     "the course's view direction with the field of view fitted to the scene's bounds",
     "pathtracer:frame_scene", PT_FIELD(p.frame_scene)},
    {"caustic_tracing", "--no-caustic-tracing", OptionType::boolean, 0, 1, 1, 1,
     "caustics through mirror and glass by light tracing (off: by path tracing alone)",
     "pathtracer:caustic_tracing", PT_FIELD(p.caustic_tracing)},
    {"default_light", "--no-default-light", OptionType::boolean, 0, 1, 1, 1,
     "light a glTF scene without lights or emitters by a white environment and a sun",
     "pathtracer:default_light", PT_FIELD(p.default_light)},
    {"tile_size", "--tile", OptionType::integer, 1, 4096, 32, 32, "tile size in pixels", "pathtracer:tile_size",
     PT_FIELD(p.tile_size)},
    {"time_limit", "--time-limit", OptionType::number, 0, 1e9, 0, 0, "stop after this many seconds (0 = none)",
     "pathtracer:time_limit", PT_FIELD(l.time_limit)},
    {"target_error", "--target-error", OptionType::number, 0, 1, 0, 0,
     "stop once the estimated relative MSE is at most this (0 = none)", "pathtracer:target_error",
     PT_FIELD(l.target_error)},
};

#undef PT_FIELD

}  // namespace

const std::vector<RenderOption>& render_options() { return kOptions; }

const RenderOption& render_option(const std::string& name) {
  for (const RenderOption& o : kOptions)
    if (name == o.name) return o;
  throw std::out_of_range("no render option '" + name + "'");
}

std::string option_text(const RenderOption& option, double value) {
  char buf[40];
  switch (option.type) {
    case OptionType::boolean: return value != 0 ? "true" : "false";
    case OptionType::integer: std::snprintf(buf, sizeof buf, "%.0f", value); return buf;
    case OptionType::real:
      // The shortest decimal that reads back as the same float: 0.05f is 0.05, not 0.0500000007.
      for (int digits = 6; digits <= 9; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, value);
        if (std::strtof(buf, nullptr) == float(value)) break;
      }
      return buf;
    case OptionType::number:
      for (int digits = 6; digits <= 17; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, value);
        if (std::strtod(buf, nullptr) == value) break;
      }
      return buf;
  }
  return "";
}

}  // namespace pt
