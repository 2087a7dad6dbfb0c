// A denoised job's part of its status, its persisted record and its image files: image.png and
// image.exr hold the denoised image and image_raw.* the raw render (GET ...?raw=1), while the error
// estimate stays the raw render's; the denoised image's is the spread of its denoised halves.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "job_store.h"
#include "jobs.h"
#include "render_backend.h"
#include "request_policy.h"

namespace srv {

json denoise_json(const Job& j) {
  if (j.spec.denoise == DenoiseMode::off) return nullptr;
  const Job::Denoised& d = j.denoised;
  json out{{"mode", denoise_mode_name(j.spec.denoise)},
           {"frames", d.frames},
           {"spp", d.frames ? json(d.spp) : json(nullptr)},
           {"seconds", d.frames ? json(d.seconds) : json(nullptr)},
           {"spent_seconds", d.spent_seconds},
           {"final", d.final},
           {"noise_estimate", d.noise >= 0 ? json(d.noise) : json(nullptr)},
           {"noise_estimate_of",
            "the denoised image: the relative MSE between the denoised images of the film's two halves of "
            "samples (its noise, not its bias); error_estimate is the raw render's"}};
  if (!d.warning.empty()) out["warning"] = d.warning;
  out["raw_images"] = {{"png", "/api/jobs/" + j.id + "/image.png?raw=1"}, {"exr", "/api/jobs/" + j.id + "/image.exr?raw=1"}};
  return out;
}

void require_denoiser(const JobSpec& spec) {
  if (spec.denoise == DenoiseMode::off || pt::Denoiser::shared().available()) return;
  throw JobError(JobErrorKind::unsupported,
                 std::string("'denoise' is \"") + denoise_mode_name(spec.denoise) + "\", but on this server " +
                     pt::Denoiser::shared().summary(),
                 "denoise");
}

void load_denoise(Job& j, const json& doc) {
  if (!doc.contains("denoise") || !doc["denoise"].is_object()) return;
  const json& d = doc["denoise"];
  auto number = [&](const char* key, double fallback) {
    return d.contains(key) && d[key].is_number() && std::isfinite(d[key].get<double>()) ? d[key].get<double>() : fallback;
  };
  j.denoised.frames = int(std::max(0.0, std::min(1e9, number("frames", 0))));
  j.denoised.spp = number("spp", 0);
  j.denoised.seconds = number("seconds", 0);
  j.denoised.spent_seconds = number("spent_seconds", 0);
  j.denoised.noise = number("noise_estimate", -1);
  j.denoised.final = d.value("final", false) == true;
  if (d.contains("warning") && d["warning"].is_string()) j.denoised.warning = to_valid_utf8(d["warning"].get<std::string>());
}

void store_job_images(const std::string& dir, const RenderResult& result, pt::Metadata meta) {
  for (const char* name : {"image_raw.png", "image_raw.exr"}) std::remove((dir + "/" + name).c_str());
  if (!result.denoised.ok) {
    retry_without_descriptors([&] { pt::write_image(result.image, dir + "/image.exr", meta); });
    retry_without_descriptors([&] { pt::write_image(result.image, dir + "/image.png"); });
    return;
  }
  // The raw render first: once image.* is denoised, its raw twin is already there.
  retry_without_descriptors([&] { pt::write_image(result.image, dir + "/image_raw.exr", meta); });
  retry_without_descriptors([&] { pt::write_image(result.image, dir + "/image_raw.png"); });
  meta.push_back({"pathtracer:denoised", pt::Denoiser::shared().summary()});
  if (std::isfinite(result.denoised.noise))
    meta.push_back({"pathtracer:denoised_noise_estimate", std::to_string(result.denoised.noise)});
  retry_without_descriptors([&] { pt::write_image(result.denoised.image, dir + "/image.exr", meta); });
  retry_without_descriptors([&] { pt::write_image(result.denoised.image, dir + "/image.png"); });
}

}  // namespace srv
