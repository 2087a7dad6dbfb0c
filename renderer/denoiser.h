// The denoiser: Intel Open Image Denoise's RT filter (OIDN 2.x, loaded at run time, so that the
// renderer builds and renders without it) on a film's mean colour with its albedo and normal
// features (Film::features). It never changes the film: the estimate, resume and merging keep
// working on the raw samples.
#pragma once

#include <string>

#include "image.h"

namespace pt {

// preview: OIDN's fast quality on the features as they are (a progressive picture at pass ends);
// final: its high quality, the features first cleaned by their own filters (cleanAux).
enum class DenoiseQuality { preview, final };
const char* denoise_quality_name(DenoiseQuality q);

// Where the library is looked for, in order: $PT_OIDN_LIB (a file; then only there); oidn/lib/
// beside the executable; this build's build/oidn/lib (scripts/install-oidn.sh); the system's
// libOpenImageDenoise.so.2 (a distribution's package, or LD_LIBRARY_PATH).
// The version this code was written for: OIDN 2.3 or later in major version 2 ("fast" quality is 2.3's).
constexpr int kOidnMinVersion = 20300, kOidnMaxVersion = 29999;
// Why a library reporting `version` (major * 10000 + minor * 100 + patch) is refused; "" when it is not.
std::string oidn_version_problem(int version);

class Denoiser {
 public:
  // The process's denoiser, loaded at the first call (from any thread).
  static Denoiser& shared();

  bool available() const { return m_api != nullptr; }
  // "Intel Open Image Denoise 2.5.1 (path)", or why it is not available and how to get it.
  const std::string& description() const { return m_description; }
  // The same without file paths, for clients of a server: "Intel Open Image Denoise 2.5.1", or
  // that it is not installed and how its operator installs it.
  std::string summary() const;
  int version() const { return m_version; }

  // Denoises `color` (linear HDR, finite, w x h) guided by `albedo` (in [0, 1]) and `normal` (in
  // [-1, 1]) of the same size into `out`, on `threads` threads. False with `error` set when the
  // library is missing or fails (out of memory, a bad size); never throws. One call at a time runs.
  bool denoise(const ImageRGB& color, const ImageRGB& albedo, const ImageRGB& normal, DenoiseQuality quality,
               int threads, ImageRGB& out, std::string& error);

  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

 private:
  Denoiser();
  ~Denoiser();
  struct Api;
  struct State;
  Api* m_api = nullptr;
  State* m_state = nullptr;
  int m_version = 0;
  std::string m_description;
};

// What a user is told where the denoiser is missing: how to install it.
extern const char* const kDenoiserInstallHint;

}  // namespace pt
