// Flag reading for the bench programs: strict, and every mistake named (status 2), never a guess.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "session.h"

namespace bench {

// Minimal flag reading: `--name value` and `--name` switches. Anything wrong (an unknown flag, a
// flag without its value, a number that is not a whole number in range) ends the program with
// status 2 and a line that names the flag.
struct Args {
  int argc;
  char** argv;
  const char* usage;
  std::string prog;  // argv[0] without its directory, as the messages name the program
  std::vector<bool> used;
  Args(int c, char** v, const char* usage_line) : argc(c), argv(v), usage(usage_line), used(size_t(c), false) {
    const char* slash = c > 0 ? std::strrchr(v[0], '/') : nullptr;
    prog = c > 0 ? (slash ? slash + 1 : v[0]) : "bench";
  }
  [[noreturn]] void fail(const std::string& what) const {
    std::fprintf(stderr, "%s: %s\nusage: %s\n", prog.c_str(), what.c_str(), usage);
    std::exit(2);
  }
  // --help or -h: prints the usage line; the caller then returns 0.
  bool help() {
    if (!flag("--help") && !flag("-h")) return false;
    std::printf("usage: %s\n", usage);
    return true;
  }
  bool flag(const char* name) {
    for (int i = 1; i < argc; ++i)
      if (!std::strcmp(argv[i], name)) return used[size_t(i)] = true;
    return false;
  }
  // The value after `name`, or nullptr when the flag is absent.
  const char* find(const char* name) {
    for (int i = 1; i < argc; ++i)
      if (!std::strcmp(argv[i], name)) {
        if (i + 1 == argc) fail(std::string(name) + " needs a value");
        used[size_t(i)] = used[size_t(i) + 1] = true;
        return argv[i + 1];
      }
    return nullptr;
  }
  std::string value(const char* name, const std::string& def) {
    const char* v = find(name);
    return v ? v : def;
  }
  int integer(const char* name, int def, int lo, int hi) {
    const char* v = find(name);
    if (!v) return def;
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(v, &end, 10);
    if (!*v || *end || errno == ERANGE || n < lo || n > hi)
      fail(std::string(name) + " must be a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
           ", not '" + v + "'");
    return int(n);
  }
  // --sampler sobol|independent (default: the renderer's default).
  pt::SamplerKind sampler() {
    std::string v = value("--sampler", "default");
    if (v == "default") return pt::RenderParams().sampler;
    if (v == "sobol") return pt::SamplerKind::sobol;
    if (v == "independent") return pt::SamplerKind::independent;
    fail("--sampler must be sobol or independent, not '" + v + "'");
  }
  // The arguments no flag took that do not look like flags, in order (call after reading the flags).
  std::vector<std::string> positional() {
    std::vector<std::string> out;
    for (int i = 1; i < argc; ++i)
      if (!used[size_t(i)] && argv[i][0] != '-') {
        used[size_t(i)] = true;
        out.push_back(argv[i]);
      }
    return out;
  }
  // Call after reading every flag: fails naming the first argument not understood.
  void finish() const {
    for (int i = 1; i < argc; ++i)
      if (!used[size_t(i)]) fail(std::string("unknown argument '") + argv[i] + "'");
  }
};

// Runs a benchmark's body: an exception (a scene that does not load, a setting the renderer
// refuses) ends it with the message and status 1 rather than an abort.
template <class Body>
int run_guarded(const char* prog, Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", prog, e.what());
    return 1;
  }
}

}  // namespace bench
