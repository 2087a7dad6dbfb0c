// render-server: the job queue behind an HTTP API, serving web/ at /.
#include <httplib.h>
#include <signal.h>
#include <sys/resource.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "connection.h"
#include "image.h"
#include "jobs.h"
#include "nearest.h"
#include "routes.h"
#include "version.h"

extern const char* kOpenApiJson;  // generated from server/openapi.json at build time

namespace {

const char* kUsage =
    "Usage: render-server [options]\n"
    "Renders queued path-tracing jobs and serves the API (/api) and the web page (/).\n"
    "  --host ADDR       address to bind (default 127.0.0.1; 0.0.0.0 opens it to the network)\n"
    "  --allowed-host NAME  a Host name to answer besides loopback names and --host (a reverse\n"
    "                    proxy's name); repeatable. Other names get 421 (DNS-rebinding defence)\n"
    "  --port N          port (default 8080; 0 picks a free one and prints it)\n"
    "  --data DIR        jobs and images (default ./data)\n"
    "  --scenes DIR      a folder of scenes (.dae, .gltf, .glb) served besides the bundled scenes/;\n"
    "                    repeatable; a name in DIR hides a bundled scene of the same name\n"
    "  --no-bundled-scenes  serve only the --scenes folders\n"
    "  --web DIR         the page to serve at / (default: the bundled web/)\n"
    "  --threads N       render threads per job (default: all cores)\n"
    "  --concurrency N   jobs rendering at once (default 1)\n"
    "  --scene-cache-mb N  built scenes (BVH, lights) kept for later jobs, in MiB; past it the least\n"
    "                    recently used one no job holds is dropped (default 1024)\n"
    "  --max-queue N     queued jobs before new ones are refused with 429 (default 32)\n"
    "  --queue URL       'embedded' (default: render here) or redis://HOST:PORT: hand sample passes\n"
    "                    to render-worker processes through Redis Streams (docs/scale-out.md)\n"
    "  --units-in-flight N  Redis: passes queued ahead of the merges per job (default 4; about\n"
    "                    the number of workers)\n"
    "  --redis-timeout SEC  Redis: seconds a job waits for an unreachable Redis, then fails (default 300)\n"
    "                    The URL may hold a user, a password and a database: redis://USER:PASS@HOST:PORT/DB\n"
    "  --redis-password-file F  Redis: the password, read from a file (or PT_REDIS_PASSWORD), kept\n"
    "                    out of the process list\n"
    "  --farm-key-file F  Redis: sign pass requests and check the workers' signed results with this\n"
    "                    shared key (HMAC-SHA256; the same file on every worker)\n"
    "  --insecure-farm   Redis: allow an unsigned farm on a Redis that is not on loopback\n"
    "  --max-scene-mb M  the largest scene PUT /api/scenes/{name} takes, in MiB (default 64).\n"
    "                    Uploaded scenes are kept in DIR/scenes of --data\n"
    "  --checkpoint-interval SEC  seconds between a running job's checkpoints, which a restart, a\n"
    "                    pause or a continue resumes exactly (default 30; 0 = after every pass)\n"
    "  --keep-jobs N     keep the newest N finished jobs; older ones are deleted with their files\n"
    "                    (default 0: keep all). Queued, running and paused jobs are never deleted\n"
    "  --max-data-mb M   delete the oldest finished jobs while the data folder is over M MiB\n"
    "                    (default 0: no cap)\n"
    "  --token T         require 'Authorization: Bearer T' on /api (all but /api/health); also read\n"
    "                    from the environment variable RENDER_SERVER_TOKEN. The page asks for it.\n"
    "  --max-connections N  open connections before new ones are answered 503 (default 128; kept\n"
    "                    below the process's file-descriptor limit)\n"
    "  --read-timeout SEC   seconds to receive a whole request, however slowly sent (default 10)\n"
    "  -h, --help        this text\n"
    "  --version         the version, git commit, Embree and OpenImageIO versions\n";

bool parse_seconds(const char* s, double* out) {
  char* end;
  double v = std::strtod(s, &end);
  if (*s == '\0' || *end != '\0' || !(v >= 0.1 && v <= 3600)) return false;
  *out = v;
  return true;
}

bool parse_int(const char* s, long lo, long hi, long* out) {
  char* end;
  long v = std::strtol(s, &end, 10);
  if (*s == '\0' || *end != '\0' || v < lo || v > hi) return false;
  *out = v;
  return true;
}

// Threads beyond the connection cap (those over it are answered 503 by a thread), and accepted
// connections that may wait for a thread.
constexpr long kExtraThreads = 16;
constexpr size_t kMaxPendingConnections = 16;

// Raises the soft descriptor limit to the hard one, and keeps the connection cap below it with room
// for the files, scenes and images jobs open: a connection flood must never leave a finished render
// unable to write its image.
int connection_cap(int wanted, int threads) {
  rlimit lim{};
  if (getrlimit(RLIMIT_NOFILE, &lim) != 0) return wanted;
  if (lim.rlim_cur < lim.rlim_max) {
    rlimit raised = lim;
    raised.rlim_cur = lim.rlim_max == RLIM_INFINITY ? std::max<rlim_t>(lim.rlim_cur, 1 << 16) : lim.rlim_max;
    if (setrlimit(RLIMIT_NOFILE, &raised) == 0) lim = raised;
  }
  // Descriptors in use at most: the reserve (job files, scene reads, image writes, logs), two per
  // connection being served (its socket and a file it may read), and the accepted connections
  // waiting for a thread (BoundedThreadPool) plus one on the accepting thread.
  long reserve = 64 + 4L * threads + kMaxPendingConnections + 1;
  long room = lim.rlim_cur == RLIM_INFINITY ? 2L * (wanted + kExtraThreads) : long(lim.rlim_cur) - reserve;
  if (room >= 2L * (wanted + kExtraThreads)) return wanted;
  int cap = int(std::max(1L, room / 2 - kExtraThreads));
  std::fprintf(stderr, "render-server: --max-connections %d lowered to %d: the descriptor limit is %llu\n", wanted, cap,
               (unsigned long long)lim.rlim_cur);
  return cap;
}

// The Host names answered: loopback names, the bound name and --allowed-host; on a non-loopback
// bind every name unless --allowed-host restricts them.
srv::HostPolicy host_policy(const std::string& bind, const std::vector<std::string>& allowed) {
  srv::HostPolicy policy;
  std::string b = bind;
  for (char& c : b) c = char(std::tolower((unsigned char)c));
  policy.loopback_only = srv::is_loopback_host(b);
  for (std::string name : allowed) {
    for (char& c : name) c = char(std::tolower((unsigned char)c));
    policy.allowed.push_back(name);
  }
  if (b != "0.0.0.0" && b != "::" && !policy.allowed.empty()) policy.allowed.push_back(b);
  if (policy.loopback_only) policy.allowed.push_back(b);
  return policy;
}

}  // namespace

int main(int argc, char** argv) {
  std::string host = "127.0.0.1", web = PT_SOURCE_DIR "/web";
  long port = 8080, n;
  srv::ManagerConfig cfg;
  cfg.threads = int(std::max(1u, std::thread::hardware_concurrency()));
  bool bundled_scenes = true;
  std::vector<std::string> allowed_hosts;
  srv::ApiOptions api;
  api.openapi = kOpenApiJson;
  if (const char* t = std::getenv("RENDER_SERVER_TOKEN")) api.token = t;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "render-server: %s needs a value (see --help)\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    auto bad = [&](const char* v) {
      std::fprintf(stderr, "render-server: bad value '%s' for %s (see --help)\n", v, a.c_str());
      std::exit(2);
    };
    if (a == "--host") host = value();
    else if (a == "--allowed-host") allowed_hosts.push_back(value());
    else if (a == "--port") { const char* v = value(); if (!parse_int(v, 0, 65535, &port)) bad(v); }
    else if (a == "--data") cfg.data_dir = value();
    else if (a == "--scenes") cfg.scene_dirs.push_back(value());
    else if (a == "--no-bundled-scenes") bundled_scenes = false;
    else if (a == "--web") web = value();
    else if (a == "--threads") { const char* v = value(); if (!parse_int(v, 1, 1024, &n)) bad(v); cfg.threads = int(n); }
    else if (a == "--concurrency") { const char* v = value(); if (!parse_int(v, 1, 64, &n)) bad(v); cfg.concurrency = int(n); }
    else if (a == "--scene-cache-mb") { const char* v = value(); if (!parse_int(v, 0, 1 << 30, &n)) bad(v); cfg.scene_cache_bytes = size_t(n) << 20; }
    else if (a == "--max-queue") { const char* v = value(); if (!parse_int(v, 0, 100000, &n)) bad(v); cfg.max_queue = size_t(n); }
    else if (a == "--queue") cfg.queue = value();
    else if (a == "--units-in-flight") { const char* v = value(); if (!parse_int(v, 1, 1024, &n)) bad(v); cfg.units_in_flight = int(n); }
    else if (a == "--redis-timeout") { const char* v = value(); if (!parse_seconds(v, &cfg.redis_timeout)) bad(v); }
    else if (a == "--redis-password-file") cfg.farm.password_file = value();
    else if (a == "--farm-key-file") cfg.farm.key_file = value();
    else if (a == "--insecure-farm") cfg.farm.insecure = true;
    else if (a == "--checkpoint-interval") {
      const char* v = value();
      char* end;
      cfg.checkpoint_interval = std::strtod(v, &end);
      if (*v == '\0' || *end != '\0' || !(cfg.checkpoint_interval >= 0 && cfg.checkpoint_interval <= 86400)) bad(v);
    }
    else if (a == "--max-scene-mb") { const char* v = value(); if (!parse_int(v, 1, 1024, &n)) bad(v); api.max_scene_bytes = size_t(n) << 20; }
    else if (a == "--keep-jobs") { const char* v = value(); if (!parse_int(v, 0, 100000000, &n)) bad(v); cfg.keep_jobs = size_t(n); }
    else if (a == "--max-data-mb") { const char* v = value(); if (!parse_int(v, 0, 1L << 40, &n)) bad(v); cfg.max_data_bytes = uint64_t(n) << 20; }
    else if (a == "--token") api.token = value();
    else if (a == "--max-connections") { const char* v = value(); if (!parse_int(v, 1, 10000, &n)) bad(v); api.limits.max_connections = int(n); }
    else if (a == "--read-timeout") { const char* v = value(); if (!parse_seconds(v, &api.limits.request_timeout)) bad(v); }
    else if (a == "-h" || a == "--help") { std::printf("%s", kUsage); return 0; }
    else if (a == "--version") { std::printf("%s\n", pt::version_text("render-server").c_str()); return 0; }
    else {
      std::vector<std::string> flags;  // every flag --help names
      for (const char* at = kUsage; (at = std::strstr(at, "  --")) != nullptr; at += 2)
        flags.emplace_back(at + 2, std::strcspn(at + 2, " \n"));
      flags.emplace_back("-h");
      const std::string near = pt::nearest_name(a, flags);
      std::fprintf(stderr, "render-server: unknown option '%s'%s (see --help)\n", a.c_str(),
                   near.empty() ? "" : (" (did you mean " + near + "?)").c_str());
      return 2;
    }
  }
  if (bundled_scenes)  // after the user's folders: theirs win a name both hold
    cfg.scene_dirs.insert(cfg.scene_dirs.end(), {PT_SOURCE_DIR "/scenes", PT_BINARY_DIR "/scenes"});

  // SIGINT/SIGTERM are taken by one thread with sigwait, so a signal never interrupts a render.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  signal(SIGXFSZ, SIG_IGN);  // a file-size limit makes a write fail (a failed job), not kill the server

  srv::JobManager jobs(cfg);
  try {
    pt::require_image_io();  // every job ends in an image: refuse to start rather than lose them
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render-server: %s\n", e.what());
    return 1;
  }
  api.limits.max_connections = connection_cap(api.limits.max_connections, cfg.threads);
  api.hosts = host_policy(host, allowed_hosts);

  // One thread per open connection (event streams hold theirs): the pool outnumbers the connection
  // cap, so connections over it are answered 503 at once instead of queueing.
  srv::GuardedServer svr(api.limits);
  int pool = api.limits.max_connections + kExtraThreads;
  svr.new_task_queue = [pool] { return new srv::BoundedThreadPool(size_t(pool), kMaxPendingConnections); };
  svr.set_write_timeout(10, 0);
  svr.set_keep_alive_max_count(100);
  svr.set_keep_alive_timeout(1);  // an idle connection holds up a shutdown this long at most
  svr.set_tcp_nodelay(true);  // headers and body go out in two writes: without it, +40 ms (delayed ACK)
  // Only SO_REUSEADDR: httplib's default SO_REUSEPORT lets a second server bind the same port and
  // silently take half its connections.
  svr.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  srv::install_routes(svr, jobs, api);
  if (!svr.set_mount_point("/", web)) std::fprintf(stderr, "render-server: warning: no web page at %s\n", web.c_str());

  errno = 0;
  int bound = port == 0 ? svr.bind_to_any_port(host) : (svr.bind_to_port(host, int(port)) ? int(port) : -1);
  if (bound < 0) {
    std::string why = errno ? std::strerror(errno) : "the address cannot be bound";
    std::fprintf(stderr, "render-server: cannot listen on %s:%ld: %s%s\n", host.c_str(), port, why.c_str(),
                 errno == EADDRINUSE ? " (is another render-server running on that port?)" : "");
    return 1;
  }
  svr.widen_backlog();
  // Jobs start once the port is ours: a second server refused above has touched nothing.
  try {
    jobs.start();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render-server: %s\n", e.what());
    return 1;
  }
  std::printf("render-server: listening on http://%s:%d/ (rendering: %s)\n", host.c_str(), bound,
              jobs.backend_name().c_str());
  std::fflush(stdout);

  std::thread signal_thread([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    std::fprintf(stderr, "render-server: %s, stopping\n", sig == SIGINT ? "SIGINT" : "SIGTERM");
    jobs.stop();  // wakes event streams and puts a running job back in the queue
    svr.stop();
  });
  svr.listen_after_bind();
  jobs.stop();
  if (signal_thread.joinable()) {
    pthread_kill(signal_thread.native_handle(), SIGTERM);
    signal_thread.join();
  }
  return 0;
}
