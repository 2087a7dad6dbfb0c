// Job spec parsing: strict types, documented defaults, limits named in every error.
#include "job_spec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
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
    if (!r.seen.count(it.key())) errors.emplace_back(it.key(), "unknown field '" + it.key() + "'");
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
  return j;
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
