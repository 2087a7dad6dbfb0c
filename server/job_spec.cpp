// Job spec parsing: strict types, documented defaults, limits named in every error.
#include "job_spec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "nearest.h"

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

// The shortest decimal that reads back as the same float (0.1f is 0.1, not 0.100000001).
double shortest(float v) {
  char buf[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, double(v));
    if (std::strtof(buf, nullptr) == v) break;
  }
  return std::strtod(buf, nullptr);
}

json vec3_json(pt::Vec3 v) { return json::array({shortest(v.x), shortest(v.y), shortest(v.z)}); }

pt::Vec3 read_vec3(const json& v, const std::string& field) {
  if (!v.is_array() || v.size() != 3)
    throw JobError(JobErrorKind::invalid, "'" + field + "' must be an array of three numbers [x, y, z]", field);
  float xyz[3];
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) throw JobError(JobErrorKind::invalid, "'" + field + "' must hold three numbers", field);
    const double x = v[i].get<double>();
    if (!std::isfinite(x) || std::fabs(x) > 1e7)
      throw JobError(JobErrorKind::invalid, "'" + field + "': each coordinate must be finite and within 1e7", field);
    xyz[i] = float(x);
  }
  return pt::Vec3(xyz[0], xyz[1], xyz[2]);
}

}  // namespace

pt::CameraPose parse_camera(const json& cam) {
  if (!cam.is_object())
    throw JobError(JobErrorKind::invalid, "'camera' must be an object {position, target, up, vfov}", "camera");
  for (auto it = cam.begin(); it != cam.end(); ++it)
    if (it.key() != "position" && it.key() != "target" && it.key() != "up" && it.key() != "vfov")
      throw JobError(JobErrorKind::invalid, "unknown field 'camera." + it.key() + "' (camera fields: position, target, up, vfov)",
                     "camera." + it.key());
  pt::CameraPose pose;
  pose.set = true;
  for (const char* need : {"position", "target"})
    if (!cam.contains(need) || cam[need].is_null())
      throw JobError(JobErrorKind::invalid, std::string("'camera.") + need + "' is required", std::string("camera.") + need);
  pose.position = read_vec3(cam["position"], "camera.position");
  pose.target = read_vec3(cam["target"], "camera.target");
  if (cam.contains("up") && !cam["up"].is_null()) pose.up = read_vec3(cam["up"], "camera.up");
  if (cam.contains("vfov") && !cam["vfov"].is_null()) {
    const json& f = cam["vfov"];
    const double v = f.is_number() ? f.get<double>() : -1;
    if (!(v >= pt::kMinPoseFov && v <= pt::kMaxPoseFov))
      throw JobError(JobErrorKind::invalid, "'camera.vfov' must be a number between 0.1 and 179 (degrees)", "camera.vfov");
    pose.vfov_deg = float(v);
  }
  const std::string why = pt::pose_error(pose);  // "part: why"
  if (!why.empty()) {
    const std::string part = "camera." + why.substr(0, why.find(':'));
    throw JobError(JobErrorKind::invalid, "'" + part + "'" + why.substr(why.find(':')), part);
  }
  return pose;
}

json camera_pose_json(const pt::CameraPose& pose) {
  if (!pose.set) return nullptr;
  return {{"position", vec3_json(pose.position)},
          {"target", vec3_json(pose.target)},
          {"up", vec3_json(pose.up)},
          {"vfov", pose.vfov_deg > 0 ? json(shortest(pose.vfov_deg)) : json(nullptr)}};
}

json view_json(const pt::Camera& c) {
  return {{"position", vec3_json(c.position)},
          {"target", vec3_json(c.target)},
          {"up", vec3_json(c.up)},
          {"vfov", shortest(pt::vertical_fov_deg(c))}};
}

std::pair<double, double> job_range(const pt::RenderOption& o, const SpecLimits& lim) {
  std::string name = o.name;
  double hi = o.max, lo = o.min;
  if (name == "width") hi = std::min(hi, double(lim.max_width));
  if (name == "height") hi = std::min(hi, double(lim.max_height));
  if (name == "spp") hi = std::min(hi, double(lim.max_spp));
  if (name == "max_depth") hi = std::min(hi, double(lim.max_depth));
  if (name == "light_samples") hi = std::min(hi, double(lim.max_light_samples));
  if (name == "tile_size") {
    lo = std::max(lo, double(lim.min_tile_size));
    hi = std::min(hi, double(lim.max_tile_size));
  }
  return {lo, hi};
}

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
  // Every field is checked, and every invalid one named at once (the first leads the answer).
  JobError::FieldErrors errors;
  auto check = [&](auto&& read) {
    try {
      read();
    } catch (const JobError& e) {
      errors.emplace_back(e.field(), e.what());
    }
  };
  check([&] {
    const json* scene = r.get("scene");
    if (!scene) throw JobError(JobErrorKind::invalid, "'scene' is required", "scene");
    if (!scene->is_string()) throw JobError(JobErrorKind::invalid, "'scene' must be a string", "scene");
    s.scene = scene->get<std::string>();
    if (!valid_scene_name(s.scene))
      throw JobError(JobErrorKind::invalid, "'scene' must be a scene name (letters, digits, '_', '-', '.'; no paths)", "scene");
  });
  check([&] {
    const json* cam = r.get("camera");
    if (cam) p.camera = parse_camera(*cam);
  });
  check([&] {
    const json* d = r.get("denoise");
    if (!d) return;
    if (!d->is_string() || !parse_denoise_mode(d->get<std::string>(), s.denoise))
      throw JobError(JobErrorKind::invalid, "'denoise' must be \"off\", \"preview\" or \"final\"", "denoise");
    p.features = s.denoise != DenoiseMode::off;
  });
  pt::RunLimits run;
  for (const pt::RenderOption& o : pt::render_options()) {  // every field from the one table
    check([&] {
      auto [lo, hi] = job_range(o, lim);
      double v = o.service;
      switch (o.type) {
        case pt::OptionType::integer: v = double(r.integer(o.name, (long long)o.service, (long long)lo, (long long)hi)); break;
        case pt::OptionType::real:
        case pt::OptionType::number: v = r.number(o.name, o.service, lo, hi); break;
        case pt::OptionType::boolean: v = r.boolean(o.name, o.service != 0) ? 1 : 0; break;
      }
      o.set(p, run, v);
    });
  }
  s.time_limit = run.time_limit;
  s.target_error = run.target_error;
  for (auto it = body.begin(); it != body.end(); ++it)
    if (!r.seen.count(it.key())) {
      std::vector<std::string> fields{"scene", "camera", "denoise"};
      for (const pt::RenderOption& o : pt::render_options()) fields.push_back(o.name);
      const std::string near = pt::nearest_name(it.key(), fields);
      errors.emplace_back(it.key(), "unknown field '" + it.key() + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)"));
    }
  if (!errors.empty()) throw JobError(JobErrorKind::invalid, std::move(errors));
  double pixel_samples = double(p.width) * p.height * p.spp;
  if (pixel_samples > lim.max_pixel_samples) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "width x height x spp = %.0f exceeds the limit of %.0f", pixel_samples,
                  lim.max_pixel_samples);
    throw JobError(JobErrorKind::invalid, buf, "spp");
  }
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {  // "name (flag): why": the field is the option's name
    const std::string what = e.what();
    const std::string name = what.substr(0, what.find(' '));
    bool known = false;
    for (const pt::RenderOption& o : pt::render_options()) known = known || name == o.name;
    throw JobError(JobErrorKind::invalid, what, known ? name : "");
  }
  return s;
}

json job_spec_to_json(const JobSpec& s) {
  json j{{"scene", s.scene}};
  pt::RunLimits run;
  run.time_limit = s.time_limit;
  run.target_error = s.target_error;
  for (const pt::RenderOption& o : pt::render_options()) {
    double v = o.get(s.params, run);
    switch (o.type) {
      case pt::OptionType::integer: j[o.name] = (long long)v; break;
      // The shortest decimal that reads back as the same float: 0.05f is 0.05, not 0.0500000007.
      case pt::OptionType::real: j[o.name] = std::strtod(pt::option_text(o, v).c_str(), nullptr); break;
      case pt::OptionType::number: j[o.name] = v; break;
      case pt::OptionType::boolean: j[o.name] = v != 0; break;
    }
  }
  j["camera"] = camera_pose_json(s.params.camera);
  j["denoise"] = denoise_mode_name(s.denoise);
  return j;
}

const char* denoise_mode_name(DenoiseMode mode) {
  switch (mode) {
    case DenoiseMode::preview: return "preview";
    case DenoiseMode::final: return "final";
    default: return "off";
  }
}

bool parse_denoise_mode(const std::string& name, DenoiseMode& mode) {
  for (DenoiseMode m : {DenoiseMode::off, DenoiseMode::preview, DenoiseMode::final})
    if (name == denoise_mode_name(m)) {
      mode = m;
      return true;
    }
  return false;
}

json job_spec_defaults() {
  json j = job_spec_to_json(parse_job_spec(json{{"scene", "default"}}));
  j.erase("scene");
  j.erase("camera");  // not a scalar: the OpenAPI document describes it
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
