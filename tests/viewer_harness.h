// The window tests' harness: the pathtracer command run as a process (popen), an Xvfb server
// of the test process's own, and the fixture that gives each test a directory with a copy of
// the Cornell box to run the window on (it skips where Xvfb is not installed).
#pragma once

#include <gtest/gtest.h>

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace viewer_test {

struct RunResult {
  int status;
  std::string output;
  double seconds;
};

inline RunResult run(const std::string& args, const std::string& env = "") {
  std::string cmd = env + " timeout 120 " + std::string(PT_PATHTRACER_SCRIPTED) + " " + args + " 2>&1";
  auto t0 = std::chrono::steady_clock::now();
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  int st = pclose(p);
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out, s};
}

inline bool on_path(const std::string& prog) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string d; std::getline(dirs, d, ':');)
    if (access((d + "/" + prog).c_str(), X_OK) == 0) return true;
  return false;
}

inline std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) if (e->d_type != DT_DIR) names.push_back(e->d_name);
    closedir(d);
  }
  return names;
}

// An Xvfb server for this test process; -displayfd lets it pick a free display itself, so tests
// running in parallel never race for one.
class Xvfb {
 public:
  ~Xvfb() {
    if (m_pid > 0) {
      kill(m_pid, SIGTERM);
      waitpid(m_pid, nullptr, 0);
    }
  }
  // Returns "" on success, else why not.
  std::string start() {
    int fds[2];
    if (pipe(fds) != 0) return "pipe failed";
    m_pid = fork();
    if (m_pid == 0) {
      close(fds[0]);
      int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, 1);
      dup2(devnull, 2);
      std::string fd = std::to_string(fds[1]);
      execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1024x768x24", "-nolisten", "tcp", nullptr);
      _exit(127);
    }
    close(fds[1]);
    std::string number;
    pollfd pfd{fds[0], POLLIN, 0};
    while (poll(&pfd, 1, 20000) > 0) {
      char c;
      if (read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    close(fds[0]);
    if (number.empty()) return "Xvfb did not report a display";
    m_display = ":" + number;
    return "";
  }
  const std::string& display() const { return m_display; }

 private:
  pid_t m_pid = -1;
  std::string m_display;
};

class Viewer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!on_path("Xvfb")) return;
    s_xvfb = new Xvfb;
    s_error = s_xvfb->start();
    if (s_error.empty()) setenv("DISPLAY", s_xvfb->display().c_str(), 1);
  }
  static void TearDownTestSuite() {
    delete s_xvfb;
    s_xvfb = nullptr;
  }
  void SetUp() override {
    if (!s_xvfb) PT_CANNOT_RUN("Xvfb is not installed (package xvfb)");
    ASSERT_EQ(s_error, "") << "cannot start Xvfb";
    m_dir = pt::test::temp_dir() + "/viewer_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
    mkdir(m_dir.c_str(), 0755);
    for (const std::string& f : files_in(m_dir)) unlink((m_dir + "/" + f).c_str());  // earlier runs' files
    // The scene is copied so that S and D write next to it in a directory of our own.
    m_scene = m_dir + "/cornell.dae";
    std::ifstream in(pt::test::own_scene("cornell.dae"));
    std::ofstream(m_scene) << in.rdbuf();
  }

  // Runs the window with a script (in directory `cwd` if given); fails the test unless it exits
  // with status 0.
  RunResult run_window(const std::string& flags, const std::string& script, const std::string& cwd = "") {
    std::string path = m_dir + "/script.txt";
    std::ofstream(path) << script;
    RunResult r = run(flags + " --script " + path + " " + m_scene, cwd.empty() ? "" : "cd " + cwd + " &&");
    EXPECT_EQ(r.status, 0) << r.output;
    return r;
  }

  inline static Xvfb* s_xvfb = nullptr;
  inline static std::string s_error;
  std::string m_dir, m_scene;
};

// The value after `key` on the last line that has it ("focus 4.8 |" -> 4.8).
inline double value_after(const std::string& out, const std::string& key) {
  size_t at = out.rfind(key);
  if (at == std::string::npos) return NAN;
  return std::strtod(out.c_str() + at + key.size(), nullptr);
}

inline std::string last_line_with(const std::string& out, const std::string& prefix) {
  std::istringstream in(out);
  std::string found;
  for (std::string l; std::getline(in, l);)
    if (l.rfind(prefix, 0) == 0) found = l;
  return found;
}


inline bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace viewer_test
