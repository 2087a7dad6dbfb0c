// The render options (RenderParams, RunLimits) and the one table that describes them: name, type,
// range, the course's default (the CLI's) and the job service's, help, and where each lives. From it come the CLI's value
// ranges, RenderParams::validate, the job service's JSON fields (names, defaults, ranges), the
// render metadata keys; tests/test_options.cpp checks the OpenAPI document's job fields against it.
// The job service may narrow a range by policy (server/job_spec.h, SpecLimits), never widen it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "camera.h"
#include "sampler.h"

namespace pt {

struct RenderParams {
  int spp = 1;                     // -s: camera rays per pixel
  int light_samples = 1;           // -l: samples per area / environment / ambient light
  int max_depth = 1;               // -m: maximum ray depth (bounces; each specular event uses one)
  int threads = 1;                 // -t
  float lens_radius = 0;           // -b (the course calls it aperture)
  float focal_distance = float(kCourseFocalDistance);  // -d
  int width = 800, height = 600;   // -r
  bool adaptive = true;            // -a: on by default, as in the course
  int adaptive_batch = 32;
  float adaptive_tolerance = 0.05f;
  bool hemisphere = false;         // -H: uniform hemisphere direct lighting
  std::string env_map;             // -e: lat-long OpenEXR environment
  std::string camera_file;         // -c
  bool file_camera = false;        // --file-camera: the scene's camera as authored
  bool keep_fov = false;           // --keep-fov: -r scales the course's view instead of cropping it
  bool frame_scene = false;        // --frame-scene: the course's view direction, zoomed to fit the scene
  CameraPose camera;               // --camera / a job's camera field: an explicit pose after the framing
  int cell_x = 0, cell_y = 0, cell_w = 0, cell_h = 0;  // -p: window, bottom-left origin; w = 0: full frame
  uint64_t seed = 0;               // --seed
  int tile_size = 32;
  SamplerKind sampler = SamplerKind::sobol;  // --sampler: sobol (Owen-scrambled) or independent
  bool caustic_tracing = true;     // --no-caustic-tracing: caustics by light tracing where it applies
  bool default_light = true;       // --no-default-light: no default light for an unlit glTF scene
  // The denoiser's albedo and normal sums beside the colour (--denoise, a job's denoise field): a
  // render that is not denoised pays nothing for them.
  bool features = false;

  // Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
};

// Halting conditions shared by the CLI, the server and the window.
struct RunLimits {
  double time_limit = 0;     // seconds of rendering; 0 = none
  double target_error = 0;   // stop once error_estimate() <= this; 0 = none
};

enum class OptionType {
  integer,  // a whole number
  real,     // a float in RenderParams (written as the shortest decimal that reads back the same)
  number,   // a double
  boolean,
};

struct RenderOption {
  const char* name;   // the job field and the metadata key's suffix ("max_depth")
  const char* flag;   // the CLI flag that sets it ("-m", "--tile"), or "" where the CLI has none
  OptionType type;
  double min, max;    // the accepted range, the same for the CLI, jobs and RenderParams::validate
  double course;      // the CLI's default: the course program's (RenderParams' and RunLimits' own)
  double service;     // the job service's default
  const char* help;   // one line
  const char* metadata;  // the render metadata key ("pathtracer:max_depth")
  double (*get)(const RenderParams&, const RunLimits&);
  void (*set)(RenderParams&, RunLimits&, double);
};

// Every option, in the order --help and the OpenAPI document list them.
const std::vector<RenderOption>& render_options();
// The option named `name`; throws std::out_of_range for an unknown one.
const RenderOption& render_option(const std::string& name);
// A value of `option` as text: integers without a fraction, reals as their shortest decimal,
// booleans as true / false.
std::string option_text(const RenderOption& option, double value);

}  // namespace pt
