// The error-vs-time benchmarks keep building and running: each binary in --smoke mode (our
// dof.dae, 64x48, a few spp) exits 0 and prints its table header. No timing is checked.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "test_util.h"

namespace {

// Runs a command, returns its exit status; its stdout and stderr go to `out`.
int run(const std::string& cmd, std::string& out) {
  out.clear();
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void expect_runs(const std::string& binary, const std::string& flags, const std::string& header) {
  std::string out;
  int rc = run(std::string(PT_BENCH_DIR) + "/" + binary + " --smoke" + flags, out);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find(header), std::string::npos) << "no table header '" << header << "' in:\n" << out;
}

}  // namespace

TEST(BenchSmoke, Convergence) {
  std::string dir = pt::test::temp_dir() + "/bench_smoke";
  expect_runs("bench_convergence", " --out " + dir + " --cache " + dir,
              "scene         m   spp   seconds  samples/s     rays/s rays/spl     relMSE");
  EXPECT_TRUE(pt::test::file_exists(dir + "/convergence_dof_m5_sobol.csv"));
  EXPECT_TRUE(pt::test::file_exists(dir + "/convergence_dof_m5_sobol.png"));
}

TEST(BenchSmoke, Ceiling) { expect_runs("bench_ceiling", "", "replay 1    replay 16  PT/replay"); }

TEST(BenchSmoke, Scaling) { expect_runs("bench_scaling", "", "samples/s 1t samples/s 2t   2t/1t"); }

TEST(BenchSmoke, UnknownFlagIsRefused) {
  std::string out;
  EXPECT_EQ(run(std::string(PT_BENCH_DIR) + "/bench_scaling --no-such-flag", out), 2) << out;
}
