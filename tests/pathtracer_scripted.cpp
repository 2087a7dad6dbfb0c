// The test build of the pathtracer command: the shipped command plus `--script FILE`, which drives
// the debug window from a file (renderer/cmd/viewer_script.h). The window tests run this binary.
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "viewer.h"
#include "viewer_script.h"

int main(int argc, char** argv) {
  std::vector<std::string> args;
  std::unique_ptr<pt::viewer::ScriptPlayer> script;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) != "--script") {
      args.push_back(argv[i]);
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "pathtracer: --script needs a FILE\n");
      return 1;
    }
    try {
      script = std::make_unique<pt::viewer::ScriptPlayer>(argv[++i]);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "pathtracer: %s\n", e.what());
      return 1;
    }
  }
  return pt::pathtracer_main(args, argv[0], script.get());
}
