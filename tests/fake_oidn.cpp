// A stand-in for Intel Open Image Denoise's C API (the part renderer/denoiser.cpp calls), for the
// tests of what a broken or foreign library does: PT_OIDN_LIB points at it. Its "version" is
// $FAKE_OIDN_VERSION (default 20501); with $FAKE_OIDN_FAIL set, executing a filter fails as out
// of memory; otherwise a filter copies its colour to its output (a denoiser that does nothing),
// with $FAKE_OIDN_NAN set putting NaNs in it. With $FAKE_OIDN_COUNT set it says at exit how many
// filters were made (the renderer keeps its filters from call to call).
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

// The handle types at global scope, as OIDN's header and renderer/denoiser.cpp declare them: the
// functions below then have the exact types the renderer calls them through (UBSan checks that).
struct OIDNDeviceImpl {
  int error = 0;
};
struct OIDNFilterImpl {
  OIDNDeviceImpl* device;
  float *color = nullptr, *output = nullptr;
  size_t bytes = 0;
};
using Device = OIDNDeviceImpl;
using Filter = OIDNFilterImpl;

namespace {
int g_filters_made = 0;
struct ReportAtExit {
  ~ReportAtExit() {
    if (std::getenv("FAKE_OIDN_COUNT")) std::fprintf(stderr, "fake-oidn: %d filters made\n", g_filters_made);
  }
} g_report;
}  // namespace

extern "C" {
Device* oidnNewDevice(int) { return new Device; }
void oidnCommitDevice(Device*) {}
void oidnReleaseDevice(Device* d) { delete d; }
int oidnGetDeviceInt(Device*, const char* name) {
  const char* v = std::getenv("FAKE_OIDN_VERSION");
  return std::strcmp(name, "version") == 0 ? (v ? std::atoi(v) : 20501) : 0;
}
void oidnSetDeviceInt(Device*, const char*, int) {}
void oidnSetDeviceBool(Device*, const char*, bool) {}
int oidnGetDeviceError(Device* d, const char** message) {
  const int e = d->error;
  d->error = 0;
  if (message) *message = e ? "fake: cannot allocate the filter's memory" : nullptr;
  return e;
}
Filter* oidnNewFilter(Device* d, const char*) {
  ++g_filters_made;
  return new Filter{d};
}
void oidnSetSharedFilterImage(Filter* f, const char* name, void* ptr, int, size_t w, size_t h, size_t, size_t, size_t) {
  if (std::strcmp(name, "color") == 0) f->color = static_cast<float*>(ptr);
  if (std::strcmp(name, "output") == 0) f->output = static_cast<float*>(ptr);
  f->bytes = w * h * 3 * sizeof(float);
}
void oidnSetFilterBool(Filter*, const char*, bool) {}
void oidnSetFilterInt(Filter*, const char*, int) {}
void oidnCommitFilter(Filter*) {}
void oidnExecuteFilter(Filter* f) {
  if (std::getenv("FAKE_OIDN_FAIL")) {
    f->device->error = 4;  // OIDN_ERROR_OUT_OF_MEMORY
    return;
  }
  if (f->color && f->output && f->color != f->output) std::memcpy(f->output, f->color, f->bytes);
  if (f->output && std::getenv("FAKE_OIDN_NAN"))  // a library that writes garbage
    for (size_t i = 0; i < f->bytes / sizeof(float); i += 7) f->output[i] = std::nanf("");
}
void oidnReleaseFilter(Filter* f) { delete f; }
}
