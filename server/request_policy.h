// The parts of a request the server interprets itself, as pure functions over untrusted bytes:
// text encoding (UTF-8 checks, repair and clipping), the body's media type, which Host names a
// loopback server answers (DNS rebinding), whether a request comes from another site (CSRF), and
// Range headers. Kept free of httplib so they can be unit-tested and fuzzed (tests/fuzz_http.cpp).
#pragma once

#include <string>
#include <vector>

namespace srv {

// True when `s` is well-formed UTF-8 (RFC 3629: no overlongs, surrogates or code points past 10FFFF).
bool valid_utf8(const std::string& s);
// `s` with every ill-formed sequence replaced by U+FFFD: safe to put in JSON.
std::string to_valid_utf8(const std::string& s);
// At most `max_bytes` of `s` without cutting a multibyte character, "..." appended when clipped.
std::string clip_utf8(const std::string& s, size_t max_bytes);

// The media type of a Content-Type value, lower-cased, parameters and spaces dropped
// ("Application/JSON; charset=utf-8" -> "application/json"); "" when it is not type/subtype.
std::string media_type(const std::string& content_type);

// A Host header split into its host and port ("[::1]:8080" -> "::1", "8080"); false when malformed.
bool split_host(const std::string& host_header, std::string& host, std::string& port);
// True for names and addresses that always mean this machine: localhost (and *.localhost),
// 127.0.0.0/8 and ::1.
bool is_loopback_host(const std::string& host);

// Which Host headers a server answers. Bound to a loopback address, a DNS-rebinding page reaches it
// under a name of the attacker's: only loopback names, the bound address and `allowed` pass.
// Bound elsewhere (0.0.0.0, a LAN address) every Host passes unless `allowed` names some.
struct HostPolicy {
  bool loopback_only = true;        // the server is bound to a loopback address
  std::vector<std::string> allowed;  // --host and --allowed-host names, lower-case, without port

  bool allows(const std::string& host_header) const;
};

// True when a state-changing request was sent by a page of another site: `Sec-Fetch-Site:
// cross-site`, or an Origin whose host differs from the Host the request was sent to. Requests
// without either header (curl, scripts) are not cross-site.
bool cross_site_request(const std::string& origin, const std::string& sec_fetch_site, const std::string& host_header);

// How many ranges a Range header asks for (0 for an empty or unparsable header, which is served as
// no Range). More than one would make httplib build a multipart answer whole in memory.
int count_ranges(const std::string& range_header);

}  // namespace srv
