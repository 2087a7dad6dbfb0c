// What a binary says of itself (--version, the EXR header, /api/health): the project's version,
// the git commit it was built from, and the Embree and OpenImageIO it was built against.
#pragma once

#include <string>

namespace pt {

struct VersionInfo {
  const char* version;      // the project's (CMakeLists.txt)
  const char* commit;       // git describe at configure time; "unknown" outside a git checkout
  const char* embree;       // the Embree 3 and OpenImageIO versions found at configure time
  const char* openimageio;
};
const VersionInfo& version_info();
// One line: "PROGRAM VERSION (commit C), Embree E, OpenImageIO O".
std::string version_text(const std::string& program);

}  // namespace pt
