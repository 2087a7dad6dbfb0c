// The pathtracer command's flags (the course's, unchanged, plus a few long options).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "session.h"

namespace pt {

struct CliOptions {
  RenderParams params;
  std::string scene_path;
  std::string output;      // -f; empty opens the debug window
  bool help = false;
  bool version = false;    // --version
  bool spp_given = false;  // -s was on the command line (hints and the error target read it)
  bool quiet = false;      // --quiet: no progress bar
  std::string output_dir;  // --output-dir: where the window's S and D keys write (empty: the current directory)
  bool describe = false;   // --describe: print the feature set and memory, no render
  bool denoise = false;    // --denoise: write the denoised image (Intel Open Image Denoise)
  std::string error_log;   // --error-log: CSV of the error per pass
  std::string progress_log;  // --progress-log: CSV of the progress bar's fraction and ETA
  std::string reference;   // --reference: true error against this image
  RunLimits limits;        // --target-error, --time-limit
  std::string checkpoint;  // --checkpoint: resume from and save to this file
  double checkpoint_interval = 30;  // --checkpoint-interval: seconds between saves (0: every pass)
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses argv; throws UsageError naming the flag on anything malformed.
CliOptions parse_cli(const std::vector<std::string>& args);
std::string usage_text(const std::string& program);
// The options --help lists ("-s", "--keep-fov", ...), and the one or two nearest a mistyped one
// ("--sampels": "-s or --sampler", for a long spelling of a one-letter flag counts; "" if none is near).
std::vector<std::string> cli_option_names();
std::string nearest_option(const std::string& given);
// The debug window's keys: what to press, a brief phrase for the window's panel (which must fit a
// 320x240 window), the whole description for --help and the terminal.
struct WindowKey {
  const char* keys;
  const char* brief;
  const char* text;  // lines after the first indented by two spaces
};
const std::vector<WindowKey>& window_keys();
// The keys as --help lists them, one a line (part of usage_text; the window's ? prints it).
std::string window_keys_text();
// The EXR header of a render: its parameters, achieved samples, wall time and error estimate.
Metadata render_metadata(const CliOptions& options, const RenderSession& session);
// The course's rate-image name: drop the last 4 characters of the output name, add "_rate.png".
std::string rate_image_path(const std::string& output);

}  // namespace pt
