// The denoiser (denoiser.h): Intel Open Image Denoise loaded with dlopen. The part of its C API
// used here is declared below (OIDN 2.x, include/OpenImageDenoise/oidn.h); the library's own
// version is checked before anything runs.
#include "denoiser.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>

// OIDN's handle types, declared as its C header declares them (at global scope), so that a call
// through the pointers below has the library's own function type.
struct OIDNDeviceImpl;
struct OIDNFilterImpl;

namespace pt {

const char* const kDenoiserInstallHint =
    "install it with scripts/install-oidn.sh (OIDN 2.5.1 from PyPI into build/oidn), or point PT_OIDN_LIB at "
    "a libOpenImageDenoise.so.2 of OIDN 2.3 or later (README, \"Denoising\")";

const char* denoise_quality_name(DenoiseQuality q) { return q == DenoiseQuality::final ? "final" : "preview"; }

std::string oidn_version_problem(int version) {
  if (version >= kOidnMinVersion && version <= kOidnMaxVersion) return "";
  const std::string v = std::to_string(version / 10000) + "." + std::to_string(version / 100 % 100) + "." +
                        std::to_string(version % 100);
  return "Open Image Denoise " + v + " is not supported (2.3 or later in 2.x is)";
}

namespace {

using Device = OIDNDeviceImpl*;
using Filter = OIDNFilterImpl*;
constexpr int kCpuDevice = 1;   // OIDN_DEVICE_TYPE_CPU
constexpr int kFloat3 = 3;      // OIDN_FORMAT_FLOAT3
constexpr int kOutOfMemory = 4; // OIDN_ERROR_OUT_OF_MEMORY
constexpr int kQualityFast = 4, kQualityHigh = 6;

std::string executable_dir() {
  char path[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "";
  std::string p(path, size_t(n));
  return p.substr(0, p.rfind('/'));
}

}  // namespace

struct Denoiser::Api {
  void* lib = nullptr;
  Device (*oidnNewDevice)(int);
  void (*oidnCommitDevice)(Device);
  void (*oidnReleaseDevice)(Device);
  int (*oidnGetDeviceInt)(Device, const char*);
  void (*oidnSetDeviceInt)(Device, const char*, int);
  void (*oidnSetDeviceBool)(Device, const char*, bool);
  int (*oidnGetDeviceError)(Device, const char**);
  Filter (*oidnNewFilter)(Device, const char*);
  void (*oidnSetSharedFilterImage)(Filter, const char*, void*, int, size_t, size_t, size_t, size_t, size_t);
  void (*oidnSetFilterBool)(Filter, const char*, bool);
  void (*oidnSetFilterInt)(Filter, const char*, int);
  void (*oidnCommitFilter)(Filter);
  void (*oidnExecuteFilter)(Filter);
  void (*oidnReleaseFilter)(Filter);

  // Loads `path`; "" on success, else what went wrong.
  std::string load(const std::string& path) {
    lib = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* e = dlerror();
      return e ? e : "dlopen failed";
    }
    std::string missing;
    auto get = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
      if (!fn && missing.empty()) missing = name;
    };
    get(oidnNewDevice, "oidnNewDevice"), get(oidnCommitDevice, "oidnCommitDevice");
    get(oidnReleaseDevice, "oidnReleaseDevice"), get(oidnGetDeviceInt, "oidnGetDeviceInt");
    get(oidnSetDeviceInt, "oidnSetDeviceInt"), get(oidnSetDeviceBool, "oidnSetDeviceBool");
    get(oidnGetDeviceError, "oidnGetDeviceError"), get(oidnNewFilter, "oidnNewFilter");
    get(oidnSetSharedFilterImage, "oidnSetSharedFilterImage"), get(oidnSetFilterBool, "oidnSetFilterBool");
    get(oidnSetFilterInt, "oidnSetFilterInt"), get(oidnCommitFilter, "oidnCommitFilter");
    get(oidnExecuteFilter, "oidnExecuteFilter"), get(oidnReleaseFilter, "oidnReleaseFilter");
    if (missing.empty()) return "";
    dlclose(lib);
    lib = nullptr;
    return path + " is not Open Image Denoise 2 (no " + missing + ")";
  }
  // The device's last error: "" when none.
  std::string error(Device d, bool* out_of_memory = nullptr) const {
    const char* message = nullptr;
    const int code = oidnGetDeviceError(d, &message);
    if (out_of_memory) *out_of_memory = code == kOutOfMemory;
    if (code == 0) return "";
    return std::string(code == kOutOfMemory ? "out of memory: " : "") + (message ? message : "error " + std::to_string(code));
  }
  Device new_device(int threads, std::string& err) const {
    Device d = oidnNewDevice(kCpuDevice);
    if (!d) {
      err = "no CPU device";
      return nullptr;
    }
    oidnSetDeviceInt(d, "numThreads", threads);
    oidnSetDeviceBool(d, "setAffinity", false);  // the render threads share these cores
    oidnCommitDevice(d);
    err = error(d);
    if (!err.empty()) {
      oidnReleaseDevice(d);
      return nullptr;
    }
    return d;
  }
};

// Devices by thread count, and for each quality the filters of the last size it ran (a progressive
// preview denoises the same size at every pass; a filter's commit sets up its network).
struct Denoiser::State {
  std::mutex mutex;
  struct Filters {
    int width = 0, height = 0;
    DenoiseQuality quality = DenoiseQuality::preview;
    Filter main = nullptr, albedo = nullptr, normal = nullptr;
  };
  struct DeviceFilters {
    Device device = nullptr;
    Filters filters[2];  // one set per quality: callers that alternate (--error-log) rebuild nothing
  };
  std::map<int, DeviceFilters> devices;
  std::vector<Vec3> albedo, normal;  // the cleaned features (final quality)
};

Denoiser& Denoiser::shared() {
  static Denoiser* d = new Denoiser();  // never destroyed: OIDN's threads may outlive static destructors
  return *d;
}

Denoiser::Denoiser() : m_state(new State) {
  std::vector<std::string> candidates;
  const char* env = std::getenv("PT_OIDN_LIB");
  if (env && *env) {
    candidates.push_back(env);
  } else {
    const std::string dir = executable_dir();
    if (!dir.empty()) candidates.push_back(dir + "/oidn/lib/libOpenImageDenoise.so.2");
#ifdef PT_OIDN_BUILD_LIB
    candidates.push_back(PT_OIDN_BUILD_LIB);
#endif
    candidates.push_back("libOpenImageDenoise.so.2");
  }
  std::string why;
  for (const std::string& path : candidates) {
    if (path.find('/') != std::string::npos && access(path.c_str(), R_OK) != 0) {
      if (why.empty()) why = path + ": no such file";
      continue;
    }
    auto api = std::make_unique<Api>();
    std::string err = api->load(path);
    if (!err.empty()) {
      why = err;
      continue;
    }
    std::string dev_err;
    Device d = api->new_device(1, dev_err);
    if (!d) {
      why = path + ": " + dev_err;
      continue;
    }
    m_version = api->oidnGetDeviceInt(d, "version");
    api->oidnReleaseDevice(d);
    const std::string problem = oidn_version_problem(m_version);
    if (!problem.empty()) {
      why = path + ": " + problem;
      continue;
    }
    m_api = api.release();
    m_description = "Intel Open Image Denoise " + std::to_string(m_version / 10000) + "." +
                    std::to_string(m_version / 100 % 100) + "." + std::to_string(m_version % 100) + " (" + path + ")";
    return;
  }
  m_description = "the denoiser (Intel Open Image Denoise) is not installed";
  if (!why.empty()) m_description += " (" + why + ")";
  m_description += std::string("; ") + kDenoiserInstallHint;
}

Denoiser::~Denoiser() = default;

std::string Denoiser::summary() const {
  if (m_api) return m_description.substr(0, m_description.find(" ("));
  return "the denoiser (Intel Open Image Denoise) is not installed; scripts/install-oidn.sh installs it";
}

bool Denoiser::denoise(const ImageRGB& color, const ImageRGB& albedo, const ImageRGB& normal, DenoiseQuality quality,
                       int threads, ImageRGB& out, std::string& error) {
  if (!m_api) {
    error = m_description;
    return false;
  }
  const int w = color.width, h = color.height;
  const size_t n = size_t(w) * size_t(h);
  if (w < 1 || h < 1 || color.pixels.size() != n || albedo.pixels.size() != n || normal.pixels.size() != n) {
    error = "denoiser: the colour and features differ in size";
    return false;
  }
  std::lock_guard<std::mutex> lock(m_state->mutex);
  const Api& api = *m_api;
  State::DeviceFilters& df = m_state->devices[std::max(1, threads)];
  if (!df.device && !(df.device = api.new_device(std::max(1, threads), error))) {
    m_state->devices.erase(std::max(1, threads));
    error = "denoiser: " + error;
    return false;
  }
  const bool clean = quality == DenoiseQuality::final;
  State::Filters& f = df.filters[clean ? 1 : 0];
  if (!f.main || f.width != w || f.height != h || f.quality != quality) {
    for (Filter* x : {&f.main, &f.albedo, &f.normal})
      if (*x) api.oidnReleaseFilter(*x), *x = nullptr;
    f = State::Filters{w, h, quality, api.oidnNewFilter(df.device, "RT"), nullptr, nullptr};
    if (clean) f.albedo = api.oidnNewFilter(df.device, "RT"), f.normal = api.oidnNewFilter(df.device, "RT");
  }
  out.width = w, out.height = h;
  out.pixels.resize(n);
  auto image = [&](Filter filter, const char* name, const std::vector<Vec3>& px) {
    api.oidnSetSharedFilterImage(filter, name, const_cast<Vec3*>(px.data()), kFloat3, size_t(w), size_t(h), 0, 0, 0);
  };
  const int q = clean ? kQualityHigh : kQualityFast;
  const std::vector<Vec3>* a = &albedo.pixels;
  const std::vector<Vec3>* nn = &normal.pixels;
  if (clean) {  // the features through their own filters first, as OIDN's documentation does for cleanAux
    m_state->albedo = albedo.pixels, m_state->normal = normal.pixels;
    a = &m_state->albedo, nn = &m_state->normal;
    image(f.albedo, "albedo", *a), image(f.albedo, "output", *a);
    image(f.normal, "normal", *nn), image(f.normal, "output", *nn);
    for (Filter x : {f.albedo, f.normal}) {
      api.oidnSetFilterInt(x, "quality", q);
      api.oidnCommitFilter(x);
      api.oidnExecuteFilter(x);
    }
  }
  image(f.main, "color", color.pixels), image(f.main, "albedo", *a), image(f.main, "normal", *nn);
  image(f.main, "output", out.pixels);
  api.oidnSetFilterBool(f.main, "hdr", true);
  api.oidnSetFilterBool(f.main, "cleanAux", clean);
  api.oidnSetFilterInt(f.main, "quality", q);
  api.oidnCommitFilter(f.main);
  api.oidnExecuteFilter(f.main);
  bool oom = false;
  const std::string err = api.error(df.device, &oom);
  if (!err.empty()) {
    error = "denoiser: " + err;
    // A device in error may hold half-built filters: start afresh on the next call.
    for (Filter* x : {&f.main, &f.albedo, &f.normal})
      if (*x) api.oidnReleaseFilter(*x), *x = nullptr;
    return false;
  }
  return true;
}

}  // namespace pt
