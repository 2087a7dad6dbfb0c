// The pathtracer command's flags (the course's, unchanged, plus a few long options).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "render.h"

namespace pt {

struct CliOptions {
  RenderParams params;
  std::string scene_path;
  std::string output;      // -f; empty opens the debug window
  bool help = false;
  bool quiet = false;      // --quiet: no progress bar
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses argv; throws UsageError naming the flag on anything malformed.
CliOptions parse_cli(const std::vector<std::string>& args);
std::string usage_text(const std::string& program);
// The course's rate-image name: drop the last 4 characters of the output name, add "_rate.png".
std::string rate_image_path(const std::string& output);

}  // namespace pt
