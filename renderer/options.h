// The one table of render options: name, type, range, the course's default (the CLI's) and the job
// service's, help, and where each lives in RenderParams / RunLimits. From it come the CLI's value
// ranges, RenderParams::validate, the job service's JSON fields (names, defaults, ranges), the
// render metadata keys; tests/test_options.cpp checks the OpenAPI document's job fields against it.
// The job service may narrow a range by policy (server/job_spec.h, SpecLimits), never widen it.
#pragma once

#include <string>
#include <vector>

#include "render.h"

namespace pt {

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
