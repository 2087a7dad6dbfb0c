// Flag parsing for the pathtracer command, matching the course's getopt string
// "s:l:t:m:e:h:H:f:r:c:b:d:a:p:" with its multi-word -r, -a and -p.
#include "cli.h"

#include "nearest.h"
#include "options.h"
#include "version.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <thread>

namespace pt {

namespace {

long parse_int(const std::string& flag, const std::string& s, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno == ERANGE) throw UsageError(flag + ": '" + s + "' is not an integer");
  if (v < lo || v > hi)
    throw UsageError(flag + ": " + s + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

double parse_float(const std::string& flag, const std::string& s, double lo, double hi) {
  char* end = nullptr;
  errno = 0;
  double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0') throw UsageError(flag + ": '" + s + "' is not a number");
  if (!std::isfinite(v)) throw UsageError(flag + ": '" + s + "' is not finite");
  if (v < lo || v > hi) {
    char range[64];
    std::snprintf(range, sizeof range, " is out of range [%g, %g]", lo, hi);
    throw UsageError(flag + ": " + s + range);
  }
  return v;
}

// A flag's value for the render option `name`, in the option's range (options.h).
double parse_option(const std::string& flag, const char* name, const std::string& s) {
  const RenderOption& o = render_option(name);
  if (o.type == OptionType::integer) return double(parse_int(flag, s, long(o.min), long(o.max)));
  return parse_float(flag, s, o.min, o.max);
}

}  // namespace

std::vector<std::string> cli_option_names() {
  // The options --help lists: each help line that starts with "  -" names one (or two: "-h, --help").
  std::vector<std::string> names;
  std::istringstream help(usage_text("pathtracer"));
  for (std::string line; std::getline(help, line);) {
    if (line.compare(0, 3, "  -") != 0) continue;
    std::istringstream words(line);
    for (std::string w; words >> w && w[0] == '-';) {
      if (w.back() == ',') w.pop_back();
      names.push_back(w);
    }
  }
  return names;
}

std::string nearest_option(const std::string& given) {
  // Long spellings of the course's one-letter flags, which a newcomer types for them (--samples
  // for -s): the option table's names, and a few words.
  std::vector<std::pair<std::string, std::string>> aliases = {
      {"--samples", "-s"}, {"--threads", "-t"}, {"--output", "-f"}, {"--file", "-f"}, {"--resolution", "-r"},
      {"--size", "-r"}, {"--environment", "-e"}, {"--cell", "-p"}, {"--camera-file", "-c"}, {"--lens-radius", "-b"},
      {"--depth", "-m"}};
  for (const RenderOption& o : render_options()) {
    if (o.flag[0] != '-' || o.flag[1] == '-' || o.flag[1] == '\0') continue;
    std::string name = std::string("--") + o.name;
    std::replace(name.begin(), name.end(), '_', '-');
    aliases.emplace_back(name, o.flag);
  }
  std::vector<std::string> candidates = cli_option_names();
  for (const auto& a : aliases) candidates.push_back(a.first);
  std::vector<std::string> picks;
  for (const std::string& near : nearest_names(given, candidates)) {
    std::string flag = near;
    for (const auto& a : aliases)
      if (a.first == near) flag = a.second;
    if (std::find(picks.begin(), picks.end(), flag) == picks.end() && flag != given) picks.push_back(flag);
    if (picks.size() == 2) break;
  }
  return picks.empty() ? "" : picks.size() == 1 ? picks[0] : picks[0] + " or " + picks[1];
}

CliOptions parse_cli(const std::vector<std::string>& args) {
  CliOptions o;
  RenderParams& p = o.params;
  size_t i = 0;
  bool threads_given = false, spp_given = false;
  auto need = [&](const std::string& flag, size_t count) {
    if (i + count >= args.size())
      throw UsageError(flag + " needs " + std::to_string(count) + " value" + (count > 1 ? "s" : ""));
  };
  for (i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-s") { need(a, 1); p.spp = int(parse_option(a, "spp", args[++i])); spp_given = true; }
    else if (a == "-l") { need(a, 1); p.light_samples = int(parse_option(a, "light_samples", args[++i])); }
    else if (a == "-t") { need(a, 1); p.threads = int(parse_int(a, args[++i], 1, 1024)); threads_given = true; }
    else if (a == "-m") { need(a, 1); p.max_depth = int(parse_option(a, "max_depth", args[++i])); }
    else if (a == "-e") { need(a, 1); p.env_map = args[++i]; }
    else if (a == "-b") { need(a, 1); p.lens_radius = float(parse_option(a, "aperture", args[++i])); }
    else if (a == "-d") { need(a, 1); p.focal_distance = float(parse_option(a, "focal_distance", args[++i])); }
    else if (a == "-f") { need(a, 1); o.output = args[++i]; if (o.output.empty()) throw UsageError("-f: empty file name"); }
    else if (a == "-r") {
      need(a, 2);
      p.width = int(parse_option(a, "width", args[++i]));
      p.height = int(parse_option(a, "height", args[++i]));
    } else if (a == "-c") { need(a, 1); p.camera_file = args[++i]; }
    else if (a == "-a") {
      need(a, 2);
      p.adaptive = true;
      p.adaptive_batch = int(parse_option(a, "adaptive_batch", args[++i]));
      p.adaptive_tolerance = float(parse_option(a, "adaptive_tolerance", args[++i]));
    } else if (a == "-p") {
      need(a, 4);
      p.cell_x = int(parse_int(a, args[++i], 0, 16384));
      p.cell_y = int(parse_int(a, args[++i], 0, 16384));
      p.cell_w = int(parse_int(a, args[++i], 1, 16384));
      p.cell_h = int(parse_int(a, args[++i], 1, 16384));
    } else if (a == "-H") { p.hemisphere = true; }
    else if (a == "-h" || a == "--help") { o.help = true; }
    else if (a == "--no-adaptive") { p.adaptive = false; }
    else if (a == "--keep-fov") { p.keep_fov = true; }
    else if (a == "--frame-scene") { p.frame_scene = true; }
    else if (a == "--version") { o.version = true; }
    else if (a == "--no-caustic-tracing") { p.caustic_tracing = false; }
    else if (a == "--no-default-light") { p.default_light = false; }
    else if (a == "--sampler") {
      need(a, 1);
      std::string v = args[++i];
      if (v == "sobol") p.sampler = SamplerKind::sobol;
      else if (v == "independent") p.sampler = SamplerKind::independent;
      else throw UsageError("--sampler: '" + v + "' is not sobol or independent");
    }
    else if (a == "--describe") { o.describe = true; }
    else if (a == "--denoise") { o.denoise = true; p.features = true; }
    else if (a == "--error-log") { need(a, 1); o.error_log = args[++i]; }
    else if (a == "--progress-log") { need(a, 1); o.progress_log = args[++i]; }
    else if (a == "--reference") { need(a, 1); o.reference = args[++i]; }
    else if (a == "--target-error") { need(a, 1); o.limits.target_error = parse_option(a, "target_error", args[++i]); }
    else if (a == "--time-limit") { need(a, 1); o.limits.time_limit = parse_option(a, "time_limit", args[++i]); }
    else if (a == "--file-camera") { p.file_camera = true; }
    else if (a == "--camera") {
      // The job service's camera field on the command line: position, target, vertical FOV (0: the
      // framing's); up is world +Y.
      need(a, 7);
      float v[7];
      for (float& x : v) x = float(parse_float(a, args[++i], -1e7, 1e7));
      p.camera.set = true;
      p.camera.position = Vec3(v[0], v[1], v[2]);
      p.camera.target = Vec3(v[3], v[4], v[5]);
      p.camera.vfov_deg = v[6];
    }
    else if (a == "--seed") { need(a, 1); p.seed = uint64_t(parse_option(a, "seed", args[++i])); }
    else if (a == "--tile") { need(a, 1); p.tile_size = int(parse_option(a, "tile_size", args[++i])); }
    else if (a == "--quiet") { o.quiet = true; }
    else if (a == "--checkpoint") {
      need(a, 1);
      o.checkpoint = args[++i];
      if (o.checkpoint.empty()) throw UsageError("--checkpoint: empty file name");
    } else if (a == "--checkpoint-interval") { need(a, 1); o.checkpoint_interval = parse_float(a, args[++i], 0, 1e9); }
    else if (a == "--output-dir") {
      need(a, 1);
      o.output_dir = args[++i];
      if (o.output_dir.empty()) throw UsageError("--output-dir: empty directory name");
    }
    else if (a.size() > 1 && a[0] == '-') {
      const std::string near = nearest_option(a);
      throw UsageError("unknown option '" + a + "'" + (near.empty() ? "" : " (did you mean " + near + "?)"));
    }
    else {
      if (!o.scene_path.empty()) throw UsageError("more than one scene file given ('" + o.scene_path + "', '" + a + "')");
      o.scene_path = a;
    }
  }
  if (o.help || o.version) return o;
  if (o.scene_path.empty()) throw UsageError("no scene file given");
  // The course renders on one thread unless told; every core gives the same image sooner.
  if (!threads_given) p.threads = std::max(1, std::min(1024, int(std::thread::hardware_concurrency())));
  // An error target without a sample budget means "until the target" (or the time limit).
  if (!spp_given && o.limits.target_error > 0) p.spp = int(render_option("spp").max);
  o.spp_given = spp_given;
  if (!o.checkpoint.empty() && o.output.empty()) throw UsageError("--checkpoint needs -f (the window keeps no checkpoint)");
  if (!o.output_dir.empty() && !o.output.empty())
    throw UsageError("--output-dir is for the window's S and D keys; -f names its own path");
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return o;
}

std::string usage_text(const std::string& program) {
  return "Usage: " + program + " [options] <scene.dae | scene.gltf | scene.glb>\n"
"Renders a CS184 COLLADA scene or a glTF 2.0 scene with a Monte Carlo path tracer (Embree 3).\n"
"\n"
"Course flags (same meaning as the CS184 pathtracer):\n"
"  -s <INT>        camera rays (samples) per pixel (default 1; 1 = one ray through the pixel centre)\n"
"  -l <INT>        samples per area / environment / ambient light (default 1)\n"
"  -t <INT>        render threads (default: every core; the course's is 1; the image is the same)\n"
"  -m <INT>        maximum ray depth (default 1): 0 = emitters only, 1 = direct light,\n"
"                  each further bounce (specular events included) needs one more level\n"
"  -e <PATH>       OpenEXR lat-long environment map, importance-sampled\n"
"  -b <FLOAT>      thin-lens lens radius, the course's 'aperture' (default 0 = pinhole)\n"
"  -d <FLOAT>      thin-lens focal distance: plane of focus along the view axis (default 4.7)\n"
"  -f <FILE>       render once to FILE (.png with the course's tone mapping, or .exr linear\n"
"                  with metadata) plus FILE minus 4 characters + '_rate.png';\n"
"                  without -f the GLFW debug window opens (keys below)\n"
"  -r <W> <H>      output size (default 800 600); keeps the course's pixel angle, so a\n"
"                  smaller size is a centred crop of the 800x600 view\n"
"  -c <PATH>       camera settings file (the course's six-line format)\n"
"  -a <INT> <FLOAT> adaptive sampling batch size and tolerance (default 32 0.05; always on)\n"
"  -p <x> <y> <dx> <dy> render only this cell (bottom-left origin) and write a dx x dy image\n"
"  -H              uniform hemisphere sampling for direct lighting instead of light sampling\n"
"  -h, --help      this text\n"
"  --version       the version, git commit, Embree and OpenImageIO versions\n"
"\n"
"Our options:\n"
"  --no-adaptive   take exactly -s samples in every pixel\n"
"  --file-camera   use the scene file's camera pose and field of view as authored instead of\n"
"                  the course's framing (which orbits the bounding box at 1.5x its diagonal)\n"
"  --seed <INT>    random seed (default 0); the same seed gives the same image at any -t\n"
"  --tile <INT>    tile size in pixels (default 32)\n"
"  --quiet         no progress bar\n"
"  --keep-fov      -r scales the course's 800x600 view to the output size instead of cropping it\n"
"  --frame-scene   the course's view direction, zoomed so the scene's bounds fill the image\n"
"  --camera <PX> <PY> <PZ> <TX> <TY> <TZ> <VFOV>  look from P at T (up +Y) with this vertical\n"
"                  field of view in degrees (0: the framing's), as a job's camera field\n"
"  --describe      print the scene's feature set and the memory it takes, then exit\n"
"  --denoise       write the image denoised by Intel Open Image Denoise (its albedo and normal\n"
"                  features are gathered beside the colour); an EXR also holds the raw colour\n"
"                  and the features as layers raw, albedo and normal. The window: starts with\n"
"                  the denoised view (key N toggles it)\n"
"  --no-caustic-tracing  render caustics (light, mirror/glass, diffuse, eye) by path tracing alone\n"
"  --no-default-light    no white environment for a glTF scene without lights or emitters\n"
"  --sampler <sobol|independent>  per-sample numbers: Owen-scrambled Sobol (default) or independent\n"
"\n"
"Error and progress against run time (the logs and --reference with -f; the window honours the limits):\n"
"  --error-log <FILE>     write one CSV row per pass: seconds, spp, error estimate (+ true error)\n"
"  --progress-log <FILE>  write CSV rows of the progress bar, after each pass and up to 10 a second\n"
"                         between: seconds, progress, ETA (-1: unknown), the sample budget's\n"
"                         fraction, 1 at a pass's end, the samples taken and predicted still to take\n"
"                         at the last pass's end\n"
"  --target-error <X>     stop once the estimated relative MSE is <= X (without -s: however many\n"
"                         samples that takes, bounded by --time-limit when given)\n"
"  --time-limit <SEC>     stop after SEC seconds of rendering\n"
"  --reference <FILE>     a converged image of the same size: log its true RMSE and relative MSE\n"
"  --checkpoint <FILE>    save the render to FILE between passes; the same command run again\n"
"                         continues it from there (the finished image is the same, bit for bit)\n"
"  --checkpoint-interval <SEC>  seconds between checkpoints (default 30; 0 = after every pass)\n"
"  --output-dir <DIR>  window only: where S and D write (default: the current directory)\n"
"\n"
"Window keys (without -f; the render restarts after each change):\n" + window_keys_text() +
"  The render follows the window's size: -r gives the initial window size.\n";
}

const std::vector<WindowKey>& window_keys() {
  static const std::vector<WindowKey> keys = {
      {"R", "restart", "restart the render"},
      {". / ,", "depth +1 / -1", "max ray depth +1 / -1 (min 0)"},
      {"L / K", "lens +/- 0.05", "lens radius +0.05 / -0.05 (min 0)"},
      {"' / ;", "focus +/- 0.1", "focal distance +0.1 / -0.1 (min 0): focal plane farther / nearer"},
      {"] / [", "spp x2 / /2", "samples per pixel x2 / /2"},
      {"= / -", "light samples x2 / /2", "light samples x2 / /2"},
      {"T / N", "rate / denoised view", "toggle the sample-rate view (with its colour legend) / the denoised view:\n"
                                        "the film denoised (Intel Open Image Denoise) after passes long enough for\n"
                                        "it to pay (a tenth of the render time at most) and at the end; the render\n"
                                        "restarts once to gather the denoiser's albedo and normal"},
      {"S", "save the image", "save <scene>_screenshot_<M>-<D>_<h>-<m>-<s>.png, .exr and _rate.png\n"
                              "in the current directory (or --output-dir)"},
      {"D", "write the camera", "write the camera settings to <scene>_cam_settings.txt (there too)"},
      {"click", "focus there", "focus the thin lens on the surface under the cursor (autofocus)"},
      {"left drag", "orbit", "orbit the camera around its target (a coarse preview while moving)"},
      {"right drag", "pan", "pan camera and target in the view plane"},
      {"wheel", "dolly", "dolly towards / away from the target"},
      {"Space", "initial camera", "back to the initial camera"},
      {"C", "cell mode", "cell mode: a left drag's rectangle is rendered alone (-p); C again: whole frame"},
      {"H (or `)", "panel on / off", "show / hide the status panel (samples, error, ETA, settings)"},
      {"? (/)", "these keys", "list these keys (in the panel and on stdout)"},
      {"Esc / Q", "quit", "quit"},
  };
  return keys;
}

std::string window_keys_text() {
  std::string out;
  for (const WindowKey& k : window_keys()) {
    std::string key = std::string("  ") + k.keys;
    key.resize(std::max<size_t>(key.size() + 1, 18), ' ');
    std::string text = k.text;
    for (size_t at = 0; (at = text.find('\n', at)) != std::string::npos; at += 19) text.insert(at + 1, std::string(18, ' '));
    out += key + text + "\n";
  }
  return out;
}

Metadata render_metadata(const CliOptions& o, const RenderSession& session) {
  const RenderParams& p = o.params;
  SessionStats st = session.stats();
  auto num = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  double pixels = double(session.width()) * session.height();
  Metadata meta{{"pathtracer:version", version_text("pathtracer")}, {"pathtracer:scene", o.scene_path}};
  for (const RenderOption& opt : render_options())  // every render option, from the one table
    meta.push_back({opt.metadata, option_text(opt, opt.get(p, o.limits))});
  Metadata run{{"pathtracer:achieved_spp", num(pixels > 0 ? st.samples / pixels : 0)},
               {"pathtracer:direct", p.hemisphere ? "hemisphere" : "light sampling"},
               {"pathtracer:caustic_light_paths", std::to_string(st.light_paths)},
               {"pathtracer:environment", p.env_map},
               {"pathtracer:threads", std::to_string(p.threads)},
               {"pathtracer:wall_seconds", num(st.seconds)},
               {"pathtracer:error_estimate", num(session.error_estimate())},
               {"pathtracer:nonfinite_samples", std::to_string(st.nonfinite)}};
  meta.insert(meta.end(), run.begin(), run.end());
  // The camera it rendered from, whatever framed it: --camera with these numbers renders it again.
  const Camera& c = session.scene().camera;
  auto exact = [](std::initializer_list<float> values) {
    std::ostringstream s;
    s.precision(9);
    for (float v : values) s << (s.tellp() > 0 ? " " : "") << v;
    return s.str();
  };
  meta.push_back({"pathtracer:view", "position " + exact({c.position.x, c.position.y, c.position.z}) + " target " +
                                         exact({c.target.x, c.target.y, c.target.z}) + " vfov " +
                                         exact({vertical_fov_deg(c)})});
  return meta;
}

std::string rate_image_path(const std::string& output) {
  std::string base = output.size() > 4 ? output.substr(0, output.size() - 4) : output;
  return base + "_rate.png";
}

}  // namespace pt
