// A render job's specification: parsed and validated from the HTTP JSON body into RenderParams,
// with every error naming its field.
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "render_scene.h"

namespace srv {

using json = nlohmann::json;

// Serialises JSON that may hold text from outside (scene files, error messages, Redis): invalid
// UTF-8 becomes U+FFFD instead of an exception. Every dump in the server goes through it.
inline std::string dump_json(const json& j, int indent = -1) {
  return j.dump(indent, ' ', false, json::error_handler_t::replace);
}

// Why the job service refuses something, in its own terms (the HTTP layer maps each kind to a
// status: http_guard.cpp). `field` names the offending field, header or parameter ("" when none).
enum class JobErrorKind {
  invalid,        // a field's value is not acceptable
  not_found,      // no such job or scene
  conflict,       // the job's state forbids it, or an idempotency key was reused
  queue_full,     // too many jobs waiting: retry later
  shutting_down,  // the server is stopping: retry later
  no_storage,     // the data folder cannot store the job
  scene_broken,   // the job's scene no longer loads
  read_only,      // a bundled scene cannot be replaced or deleted
  unsupported,    // a valid request this server cannot serve (denoising without the denoiser)
};

class JobError : public std::runtime_error {
 public:
  JobError(JobErrorKind kind, std::string message, std::string field = "")
      : std::runtime_error(std::move(message)), m_kind(kind), m_field(std::move(field)) {}
  // Every invalid field of a request at once (field, message); the first is what() and field().
  using FieldErrors = std::vector<std::pair<std::string, std::string>>;
  JobError(JobErrorKind kind, FieldErrors errors)
      : std::runtime_error(errors.at(0).second), m_kind(kind), m_field(errors.at(0).first), m_errors(std::move(errors)) {}
  JobErrorKind kind() const { return m_kind; }
  const std::string& field() const { return m_field; }
  const FieldErrors& errors() const { return m_errors; }  // empty for a single error

 private:
  JobErrorKind m_kind;
  std::string m_field;
  FieldErrors m_errors;
};

enum class DenoiseMode { off, preview, final };

struct JobSpec {
  std::string scene;          // a scene file's name without ".dae"
  pt::RenderParams params;    // threads is the server's, not the client's
  double time_limit = 0;      // seconds; 0 = none
  double target_error = 0;    // stop when the error estimate reaches this; 0 = none
  // off, preview (denoised frames at pass ends and a denoised image, fast quality) or final (the
  // same, the finished image at high quality with its noise estimate). Not off: params.features.
  DenoiseMode denoise = DenoiseMode::off;
};
// The denoise field's names: "off", "preview", "final"; parse_denoise_mode is false for any other.
const char* denoise_mode_name(DenoiseMode mode);
bool parse_denoise_mode(const std::string& name, DenoiseMode& mode);

// The job service's policy: narrower ranges than the render options' own (renderer/options.h) where a
// job would cost the shared server too much, or its watchers too many tiles.
struct SpecLimits {
  int max_width = 4096, max_height = 4096, max_spp = 65536, max_depth = 10000, max_light_samples = 64;
  int min_tile_size = 8, max_tile_size = 256;
  double max_pixel_samples = 4294967296.0;  // width * height * spp
};

// Parses a JSON body (already parsed) into a spec with defaults; throws JobError(invalid, ..., field).
JobSpec parse_job_spec(const json& body, const SpecLimits& limits = {});
json job_spec_to_json(const JobSpec& spec);
// A render option's range for jobs: its own, narrowed by the server's policy.
std::pair<double, double> job_range(const pt::RenderOption& option, const SpecLimits& limits);
// A job's camera field {position, target, up = [0, 1, 0], vfov = the framing's}; throws
// JobError(invalid) naming the part ("camera.up").
pt::CameraPose parse_camera(const json& camera);
// A job's camera field (null when the job has none) and a resolved camera as the job status shows
// it ({position, target, up, vfov}, vfov in degrees).
json camera_pose_json(const pt::CameraPose& pose);
json view_json(const pt::Camera& camera);
// The defaults and limits, as the API documents them.
json job_spec_defaults();
bool valid_scene_name(const std::string& name);
// The feature list a job's status shows (materials, lights, spheres, ...).
std::vector<std::string> feature_names(const pt::SceneFeatures& f);

}  // namespace srv
