// The error-vs-time benchmarks keep building and running: each binary in --smoke mode (our
// dof.dae, 64x48, a few spp) exits 0 and prints its table header. No timing is checked.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <regex>
#include <stdexcept>
#include <string>

#include "../bench/args.h"
#include "../bench/bench_common.h"
#include "test_util.h"

namespace {

// Runs a command, returns its exit status; its stdout and stderr go to `out`.
int run(const std::string& cmd, std::string& out) {
  pt::test::RunResult r = pt::test::run_command(cmd);
  out = r.output;
  return r.status;
}

// The benchmark's first line names the machine: its CPU model, the CPUs it may use and the widest
// vector ISA, the one this test process sees.
void expect_host_line(const std::string& out, const std::string& prog) {
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(prog + R"(: host (.+), (\d+) CPUs, (AVX-512|AVX2|SSE2)\n)"))) << out;
  EXPECT_FALSE(m[1].str().empty()) << m.str();
  EXPECT_GE(std::stoi(m[2]), 1) << m.str();
  const char* isa = __builtin_cpu_supports("avx512f") ? "AVX-512" : __builtin_cpu_supports("avx2") ? "AVX2" : "SSE2";
  EXPECT_EQ(m[3].str(), isa) << m.str();
}

std::string expect_runs(const std::string& binary, const std::string& flags, const std::string& header) {
  std::string out;
  int rc = run(std::string(PT_BENCH_DIR) + "/" + binary + " --smoke" + flags, out);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find(header), std::string::npos) << "no table header '" << header << "' in:\n" << out;
  expect_host_line(out, binary);
  return out;
}

// A ratio column of the benchmarks' tables: "median lo-hi", two decimals each.
const std::regex kRatio(R"( (\d+\.\d\d) (\d+\.\d\d)-(\d+\.\d\d) )");

// A median of ratios within their min-max, one row per scene (a mix-up of the pairs or of
// min and max fails it).
void expect_median_within_spread(const std::string& out, int rows_expected) {
  const std::regex& ratio = kRatio;
  int rows = 0;
  for (std::sregex_iterator m(out.begin(), out.end(), ratio), end; m != end; ++m, ++rows) {
    double median = std::stod((*m)[1]), lo = std::stod((*m)[2]), hi = std::stod((*m)[3]);
    EXPECT_LE(lo, median) << m->str();
    EXPECT_LE(median, hi) << m->str();
    EXPECT_GT(lo, 0) << m->str();
  }
  EXPECT_EQ(rows, rows_expected) << out;
}

// The verdict line of a benchmark's smoke run: met or not, the lowest value and its case.
struct Verdict {
  bool met;
  double lowest;
  std::string where;
};
Verdict find_verdict(const std::string& out, const std::string& what) {
  std::smatch m;
  const std::regex line("target: " + what + R"(: (met|not met) in this smoke run \(no measurement\) \(lowest (\d+\.\d\d): ([^;)]+)[;)])");
  if (!std::regex_search(out, m, line)) throw std::runtime_error("no verdict for '" + what + "' in:\n" + out);
  return {m[1] == "met", std::stod(m[2]), m[3]};
}

// The medians of the "median lo-hi" ratio columns of the table rows that start with `scene`.
std::vector<std::vector<double>> row_ratios(const std::string& out, const std::string& scene) {
  std::vector<std::vector<double>> rows;
  const std::regex row("\n" + scene + " [^\n]*");
  for (std::sregex_iterator r(out.begin(), out.end(), row), end; r != end; ++r) {
    const std::string text = r->str() + " ";
    std::vector<double> medians;
    for (std::sregex_iterator m(text.begin(), text.end(), kRatio); m != std::sregex_iterator(); ++m)
      medians.push_back(std::stod((*m)[1]));
    if (!medians.empty()) rows.push_back(medians);
  }
  return rows;
}

}  // namespace

// The verdict names the weakest case (as the tables print it, to two decimals) and counts the
// cases below the goal; NaN is a miss, never a pass.
TEST(BenchTarget, VerdictNamesTheWeakestCaseAndCountsMisses) {
  bench::TargetCheck none("x >= 1", 1.0);
  EXPECT_EQ(none.verdict(), "target: x >= 1: nothing measured");

  bench::TargetCheck met("ratio >= 0.70", 0.70);
  met.add(0.81, "a, 1 thread");
  met.add(0.6951, "b, 2 threads");  // prints as 0.70: met, as the table shows it
  met.add(0.75, "c, 1 thread");
  EXPECT_EQ(met.verdict(), "target: ratio >= 0.70: met on this host (lowest 0.70: b, 2 threads)");

  bench::TargetCheck missed("ratio >= 0.70", 0.70);
  missed.add(0.72, "a, 1 thread");
  missed.add(0.48, "b, 1 thread");
  missed.add(0.694, "c, 2 threads");
  EXPECT_EQ(missed.verdict(),
            "target: ratio >= 0.70: not met on this host (lowest 0.48: b, 1 thread; 2 of 3 cases below 0.70)");
  // A NaN is a miss and the case named, whatever comes after it.
  missed.add(std::nan(""), "d, 2 threads");
  missed.add(0.30, "e, 1 thread");
  EXPECT_EQ(missed.verdict(),
            "target: ratio >= 0.70: not met on this host (lowest nan: d, 2 threads; 4 of 5 cases below 0.70)");
  // A smoke run's verdict says that it measured nothing.
  bench::TargetCheck smoke("z >= 1", 1.0, true);
  smoke.add(1.5, "dof");
  EXPECT_EQ(smoke.verdict(), "target: z >= 1: met in this smoke run (no measurement) (lowest 1.50: dof)");
}

TEST(BenchSmoke, Convergence) {
  std::string dir = pt::test::temp_dir() + "/bench_smoke";
  const std::string out = expect_runs("bench_convergence", " --spp 16 --out " + dir + " --cache " + dir,
                                      "scene         m   spp   seconds  samples/s     rays/s rays/spl     relMSE");
  EXPECT_TRUE(pt::test::file_exists(dir + "/convergence_dof_m5_sobol.csv"));
  EXPECT_TRUE(pt::test::file_exists(dir + "/convergence_dof_m5_sobol.png"));
  // Each pass's est/true is the estimate over relMSE less the reference's noise, and the verdict
  // on the issue's factor 1.5 takes the passes from 16 spp: here the last one.
  const std::regex pass(R"(\ndof +(\d+) +\S+ +\S+ +(\S+) +\S+ +(\S+) +(\S+) +(\S+) +\S+(?=\n))");
  double worst = NAN;
  int passes = 0;
  for (std::sregex_iterator r(out.begin(), out.end(), pass), end; r != end; ++r, ++passes) {
    const std::smatch& m = *r;
    if (m[3] == "inf") continue;  // one sample a pixel: no estimate yet
    const double rel_mse = std::stod(m[2]), estimate = std::stod(m[3]), floor = std::stod(m[4]);
    const double ratio = std::stod(m[5]), expected = estimate / (rel_mse - floor);
    EXPECT_NEAR(ratio, expected, 0.005 + 0.005 * expected) << m.str();
    if (std::stoi(m[1]) >= 16) worst = std::round(100 * std::min(ratio, 1 / ratio)) / 100;
  }
  EXPECT_EQ(passes, 5) << out;  // 1, 2, 4, 8, 16 spp
  const Verdict v = find_verdict(out, R"(the estimate within 1\.5x of the true error from 16 spp, min\(est/true, true/est\) >= 0\.67)");
  EXPECT_NEAR(v.lowest, worst, 0.011) << out;  // from the printed ratio, itself rounded
  EXPECT_EQ(v.where, "dof, 16 spp") << out;
  EXPECT_EQ(v.met, v.lowest >= 0.67) << out;
}

TEST(BenchSmoke, Scaling) {
  std::string out;
  ASSERT_EQ(run(std::string(PT_BENCH_DIR) + "/bench_scaling --smoke --runs 3", out), 0) << out;
  expect_host_line(out, "bench_scaling");
  EXPECT_NE(out.find("samples/s 1t samples/s 2t   2t/1t   min-max"), std::string::npos) << out;
  EXPECT_NE(out.find("busy 1t  busy 2t   per-CPU"), std::string::npos) << out;
  expect_median_within_spread(out, 1);  // smoke: dof.dae only
  // busy (CPU over threads x wall time) lies in (0, 1]; per-CPU (a ratio of rates) is positive.
  std::smatch m;
  std::regex tail(R"( M +(\d+\.\d\d) +(\d+\.\d\d) +(\d+\.\d\d)\n)");
  ASSERT_TRUE(std::regex_search(out, m, tail)) << out;
  for (int k : {1, 2}) {
    EXPECT_GT(std::stod(m[k]), 0) << m.str();
    EXPECT_LE(std::stod(m[k]), 1.02) << m.str();
  }
  EXPECT_GT(std::stod(m[3]), 0) << m.str();
  const auto rows = row_ratios(out, "dof");
  ASSERT_EQ(rows.size(), 1u) << out;
  const Verdict v = find_verdict(out, "2t/1t >= 1\\.85 on every scene");
  EXPECT_DOUBLE_EQ(v.lowest, rows[0][0]) << out;
  EXPECT_EQ(v.where, "dof") << out;
  EXPECT_EQ(v.met, v.lowest >= 1.85) << out;
}

// --threads N sets the second column's thread count, which the header names; fewer than 2 is an
// error that says so.
TEST(BenchSmoke, ScalingThreadCount) {
  std::string out;
  ASSERT_EQ(run(std::string(PT_BENCH_DIR) + "/bench_scaling --smoke --runs 1 --threads 3", out), 0) << out;
  EXPECT_NE(out.find("samples/s 1t samples/s 3t   3t/1t   min-max"), std::string::npos) << out;
  EXPECT_NE(out.find("busy 1t  busy 3t   per-CPU"), std::string::npos) << out;
  EXPECT_NO_THROW(find_verdict(out, "3t/1t >= 2\\.78 on every scene")) << out;  // 0.925 of 3, as 1.85 is of 2
  EXPECT_EQ(run(std::string(PT_BENCH_DIR) + "/bench_scaling --smoke --threads 1", out), 2) << out;
  EXPECT_NE(out.find("--threads must be a whole number from 2 to 1024, not '1'"), std::string::npos) << out;
}

// The glTF load benchmark writes its grid, loads and builds it, and prints its figures.
TEST(BenchSmoke, GltfLoad) {
  std::string out = expect_runs("bench_gltf_load", "", "load + build");
  EXPECT_NE(out.find("bytes a triangle"), std::string::npos) << out;
  EXPECT_NE(out.find("target: a 1M-triangle glTF loaded and built in under 1 s"), std::string::npos) << out;
}

TEST(BenchSmoke, UnknownFlagIsRefused) {
  std::string out;
  EXPECT_EQ(run(std::string(PT_BENCH_DIR) + "/bench_scaling --no-such-flag", out), 2) << out;
}

// A --scene that matches nothing is an error naming the scenes, not an empty table that reads as
// a result.
TEST(BenchSmoke, SceneMatchingNothingIsRefused) {
  std::string out;
  EXPECT_EQ(run(std::string(PT_BENCH_DIR) + "/bench_scaling --scene no-such-scene", out), 2) << out;
  EXPECT_NE(out.find("--scene 'no-such-scene' matches none of: "), std::string::npos) << out;
  EXPECT_NE(out.find("dof"), std::string::npos) << out;
  EXPECT_EQ(out.find("samples/s 1t"), std::string::npos) << out;  // no table
}

// A count that is not a whole number in range, or a flag without its value, is refused by name
// before anything runs: not read as 0 (atoi), not clamped, and not an abort from the renderer's
// own check of the same setting.
TEST(BenchSmoke, NumbersAreCheckedAndNamed) {
  struct Case {
    const char* command;
    const char* message;
  };
  const Case cases[] = {
      {"bench_convergence --smoke --spp 0", "bench_convergence: --spp must be a whole number from 1 to 16777216, not '0'"},
      {"bench_scaling --smoke --spp 4x", "bench_scaling: --spp must be a whole number from 1 to 16777216, not '4x'"},
      {"bench_scaling --smoke --runs many", "bench_scaling: --runs must be a whole number from 1 to 1000, not 'many'"},
      {"bench_convergence --smoke --depth -2", "bench_convergence: --depth must be a whole number from -1 to 1000000, not '-2'"},
      {"bench_convergence --smoke --ref-spp 99999999999",
       "bench_convergence: --ref-spp must be a whole number from 1 to 16777216, not '99999999999'"},
      {"bench_convergence --smoke --out", "bench_convergence: --out needs a value"},
      {"bench_film_merge --passes 0", "bench_film_merge: --passes must be a whole number from 1 to 1000, not '0'"},
      {"bench_farm_sign --runs 0", "bench_farm_sign: --runs must be a whole number from 1 to 1000, not '0'"},
      {"bench_export_mitsuba --width 0 scene.dae out", "bench_export_mitsuba: --width must be a whole number from 1 to 16384"},
      {"bench_export_mitsuba scene.dae", "bench_export_mitsuba: needs a scene file and an output folder"},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(run(std::string(PT_BENCH_DIR) + "/" + c.command, out), 2) << c.command << "\n" << out;
    EXPECT_NE(out.find(c.message), std::string::npos) << c.command << "\n" << out;
    EXPECT_NE(out.find("usage: "), std::string::npos) << c.command << "\n" << out;
    EXPECT_EQ(out.find("terminate called"), std::string::npos) << c.command << "\n" << out;
  }
}

// An exception inside a benchmark (a scene that does not load, a setting the renderer refuses)
// becomes its message and status 1.
TEST(BenchArgs, ExceptionsEndTheRunWithTheirMessage) {
  testing::internal::CaptureStderr();
  const int rc = bench::run_guarded("bench_x", []() -> int { throw std::invalid_argument("spp (-s): must be between 1 and 16777216"); });
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(err, "bench_x: spp (-s): must be between 1 and 16777216\n");
  EXPECT_EQ(bench::run_guarded("bench_x", [] { return 0; }), 0);
}

// bench_leave_out takes positional arguments: --help prints them instead of running, a runs count
// that is not a number and an unreadable scene are errors that name the argument or the file.
TEST(BenchSmoke, LeaveOutArgumentsAreChecked) {
  const std::string bin = std::string(PT_BENCH_DIR) + "/bench_leave_out";
  std::string out;
  EXPECT_EQ(run(bin + " --help", out), 0) << out;
  EXPECT_NE(out.find("usage: bench_leave_out [runs=3] [scene.dae ...]"), std::string::npos) << out;
  EXPECT_EQ(out.find("specialised"), std::string::npos) << out;  // no benchmark ran
  EXPECT_EQ(run(bin + " five", out), 2) << out;
  EXPECT_NE(out.find("not 'five'"), std::string::npos) << out;
  const std::string missing = pt::test::temp_dir() + "/no-such-scene.dae";
  EXPECT_EQ(run(bin + " 1 " + missing, out), 1) << out;
  EXPECT_NE(out.find(missing + ": cannot open file"), std::string::npos) << out;
}
