// Job spec parsing: strict types, documented defaults, limits named in every error.
#include "job_spec.h"

#include <cmath>
#include <set>

namespace srv {

namespace {

struct Reader {
  const json& body;
  std::set<std::string> seen;

  const json* get(const char* field) {
    seen.insert(field);
    auto it = body.find(field);
    if (it == body.end() || it->is_null()) return nullptr;
    return &*it;
  }
  long long integer(const char* field, long long def, long long lo, long long hi) {
    const json* v = get(field);
    if (!v) return def;
    if (!v->is_number_integer() && !v->is_number_unsigned())
      throw JobError(JobErrorKind::invalid, std::string("'") + field + "' must be an integer", field);
    if (v->is_number_unsigned() && v->get<unsigned long long>() > (unsigned long long)hi)
      throw JobError(JobErrorKind::invalid, std::string("'") + field + "' must be at most " + std::to_string(hi), field);
    long long x = v->get<long long>();
    if (x < lo || x > hi)
      throw JobError(JobErrorKind::invalid, std::string("'") + field + "' must be between " + std::to_string(lo) + " and " + std::to_string(hi), field);
    return x;
  }
  double number(const char* field, double def, double lo, double hi) {
    const json* v = get(field);
    if (!v) return def;
    if (!v->is_number()) throw JobError(JobErrorKind::invalid, std::string("'") + field + "' must be a number", field);
    double x = v->get<double>();
    if (!std::isfinite(x)) throw JobError(JobErrorKind::invalid, std::string("'") + field + "' must be finite", field);
    if (x < lo || x > hi) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "'%s' must be between %g and %g", field, lo, hi);
      throw JobError(JobErrorKind::invalid, buf, field);
    }
    return x;
  }
  bool boolean(const char* field, bool def) {
    const json* v = get(field);
    if (!v) return def;
    if (!v->is_boolean()) throw JobError(JobErrorKind::invalid, std::string("'") + field + "' must be true or false", field);
    return v->get<bool>();
  }
};

}  // namespace

bool valid_scene_name(const std::string& name) {
  if (name.empty() || name.size() > 128) return false;
  if (!std::isalnum((unsigned char)name[0])) return false;
  for (char c : name)
    if (!(std::isalnum((unsigned char)c) || c == '_' || c == '-' || c == '.')) return false;
  return name.find("..") == std::string::npos;
}

JobSpec parse_job_spec(const json& body, const SpecLimits& lim) {
  if (!body.is_object()) throw JobError(JobErrorKind::invalid, "the request body must be a JSON object");
  Reader r{body, {}};
  JobSpec s;
  pt::RenderParams& p = s.params;
  const json* scene = r.get("scene");
  if (!scene) throw JobError(JobErrorKind::invalid, "'scene' is required", "scene");
  if (!scene->is_string()) throw JobError(JobErrorKind::invalid, "'scene' must be a string", "scene");
  s.scene = scene->get<std::string>();
  if (!valid_scene_name(s.scene))
    throw JobError(JobErrorKind::invalid, "'scene' must be a scene name (letters, digits, '_', '-', '.'; no paths)", "scene");
  p.max_depth = int(r.integer("max_depth", 5, 0, lim.max_depth));
  p.lens_radius = float(r.number("aperture", 0, 0, 1000));
  p.focal_distance = float(r.number("focal_distance", 4.7, 0, 1e6));
  p.spp = int(r.integer("spp", 64, 1, lim.max_spp));
  p.light_samples = int(r.integer("light_samples", 1, 1, lim.max_light_samples));
  p.width = int(r.integer("width", 480, 1, lim.max_width));
  p.height = int(r.integer("height", 360, 1, lim.max_height));
  p.seed = uint64_t(r.integer("seed", 0, 0, (1LL << 53)));
  p.adaptive = r.boolean("adaptive", true);
  p.adaptive_batch = int(r.integer("adaptive_batch", 32, 1, 65536));
  p.adaptive_tolerance = float(r.number("adaptive_tolerance", 0.05, 0, 1));
  p.hemisphere = r.boolean("hemisphere", false);
  p.file_camera = r.boolean("file_camera", false);
  p.keep_fov = r.boolean("keep_fov", false);
  p.caustic_tracing = r.boolean("caustic_tracing", true);
  p.tile_size = int(r.integer("tile_size", 32, 8, 256));
  s.time_limit = r.number("time_limit", 0, 0, 7 * 86400);
  s.target_error = r.number("target_error", 0, 0, 1);
  for (auto it = body.begin(); it != body.end(); ++it)
    if (!r.seen.count(it.key())) throw JobError(JobErrorKind::invalid, "unknown field '" + it.key() + "'", it.key());
  double pixel_samples = double(p.width) * p.height * p.spp;
  if (pixel_samples > lim.max_pixel_samples) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "width x height x spp = %.0f exceeds the limit of %.0f", pixel_samples,
                  lim.max_pixel_samples);
    throw JobError(JobErrorKind::invalid, buf, "spp");
  }
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw JobError(JobErrorKind::invalid, e.what());
  }
  return s;
}

namespace {
// The shortest decimal that reads back as the same float: 0.05f is written 0.05, not 0.0500000007.
double short_float(float f) {
  char buf[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, double(f));
    if (std::strtof(buf, nullptr) == f) break;
  }
  return std::strtod(buf, nullptr);
}
}  // namespace

json job_spec_to_json(const JobSpec& s) {
  const pt::RenderParams& p = s.params;
  return json{{"scene", s.scene},
              {"max_depth", p.max_depth},
              {"aperture", short_float(p.lens_radius)},
              {"focal_distance", short_float(p.focal_distance)},
              {"spp", p.spp},
              {"light_samples", p.light_samples},
              {"width", p.width},
              {"height", p.height},
              {"seed", p.seed},
              {"adaptive", p.adaptive},
              {"adaptive_batch", p.adaptive_batch},
              {"adaptive_tolerance", short_float(p.adaptive_tolerance)},
              {"hemisphere", p.hemisphere},
              {"file_camera", p.file_camera},
              {"keep_fov", p.keep_fov},
              {"caustic_tracing", p.caustic_tracing},
              {"tile_size", p.tile_size},
              {"time_limit", s.time_limit},
              {"target_error", s.target_error}};
}

json job_spec_defaults() {
  json j = job_spec_to_json(parse_job_spec(json{{"scene", "default"}}));
  j.erase("scene");
  return j;
}

std::vector<std::string> feature_names(const pt::SceneFeatures& f) {
  std::vector<std::string> out = f.materials;
  for (const std::string& l : f.lights) out.push_back(l + " light");
  if (f.spheres) out.push_back("spheres");
  if (f.environment) out.push_back("environment map");
  if (f.thin_lens) out.push_back("thin lens");
  if (f.adaptive) out.push_back("adaptive sampling");
  if (f.caustic_tracing) out.push_back("caustic light tracing");
  return out;
}

}  // namespace srv
