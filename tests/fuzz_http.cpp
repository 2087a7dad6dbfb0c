// libFuzzer target over what the server interprets in a request itself (server/request_policy.h,
// server/job_spec.h): the Content-Type, Host, Origin, Sec-Fetch-Site and Range headers, the job
// spec's JSON and scene names, and the UTF-8 repair every JSON answer relies on. The input is
// newline-separated fields, the last one the body. Built only in build-fuzz by scripts/fuzz.sh.
// A crash, a sanitizer report, an exception other than JobError, or a broken invariant (trap) is a
// finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "job_spec.h"
#include "request_policy.h"

namespace {

void require(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> field;
  size_t at = 0;
  while (field.size() < 5) {
    size_t nl = input.find('\n', at);
    if (nl == std::string::npos) break;
    field.push_back(input.substr(at, nl - at));
    at = nl + 1;
  }
  field.resize(5);
  const std::string body = input.substr(std::min(at, input.size()));
  const std::string &content_type = field[0], &host = field[1], &origin = field[2], &fetch_site = field[3],
                    &range = field[4];

  // UTF-8: repair yields valid text, leaves valid text alone; clipping never breaks valid text.
  for (const std::string* s : {&body, &host, &origin}) {
    std::string fixed = srv::to_valid_utf8(*s);
    require(srv::valid_utf8(fixed));
    require(!srv::valid_utf8(*s) || fixed == *s);
    std::string clipped = srv::clip_utf8(fixed, 17);
    require(srv::valid_utf8(clipped) && clipped.size() <= 20);
    (void)srv::dump_json(srv::json{{"message", *s}});  // never throws, whatever the bytes
  }

  std::string type = srv::media_type(content_type);
  require(type.empty() || type.find('/') != std::string::npos);
  std::string h, p;
  bool well_formed = srv::split_host(host, h, p);
  if (well_formed) require(!h.empty() && p.size() <= 5);
  srv::HostPolicy loopback, open;
  open.loopback_only = false;
  // A server bound to the network with no --allowed-host answers every well-formed Host (and a
  // request without one); a malformed one is refused everywhere.
  require(open.allows(host) == (host.empty() || well_formed));
  if (loopback.allows(host) && !host.empty()) require(srv::is_loopback_host(h));
  (void)srv::cross_site_request(origin, fetch_site, host);
  require(srv::count_ranges(range) >= 0);

  (void)srv::valid_scene_name(body);
  srv::json doc = srv::json::parse(body, nullptr, false);
  if (!doc.is_discarded()) {
    try {
      srv::JobSpec spec = srv::parse_job_spec(doc);
      srv::json back = srv::job_spec_to_json(spec);
      // What was accepted reads back as the same spec.
      require(srv::job_spec_to_json(srv::parse_job_spec(back)) == back);
    } catch (const srv::JobError&) {
    }
  }
  return 0;
}
