// The build's identity, from definitions CMakeLists.txt gives this file alone (a new commit
// recompiles nothing else). Neither Embree's nor OpenImageIO's headers are needed: their versions
// are the ones CMake found, which are the ones the binaries link.
#include "version.h"

#ifndef PT_VERSION
#define PT_VERSION "0"
#endif
#ifndef PT_GIT_COMMIT
#define PT_GIT_COMMIT "unknown"
#endif
#ifndef PT_EMBREE_VERSION
#define PT_EMBREE_VERSION "unknown"
#endif
#ifndef PT_OIIO_VERSION
#define PT_OIIO_VERSION "unknown"
#endif

namespace pt {

const VersionInfo& version_info() {
  static const VersionInfo info{PT_VERSION, PT_GIT_COMMIT, PT_EMBREE_VERSION, PT_OIIO_VERSION};
  return info;
}

std::string version_text(const std::string& program) {
  const VersionInfo& v = version_info();
  return program + " " + v.version + " (commit " + v.commit + "), Embree " + v.embree + ", OpenImageIO " +
         v.openimageio;
}

}  // namespace pt
