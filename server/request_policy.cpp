// UTF-8 checks, media types, Host and Origin checks, Range counting: see request_policy.h.
#include "request_policy.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>
#include <cstring>

namespace srv {

namespace {

// Length of the well-formed UTF-8 sequence at p (RFC 3629, table 3-7 of the Unicode standard), or 0.
size_t sequence_length(const unsigned char* p, size_t left) {
  unsigned char c = p[0];
  if (c < 0x80) return 1;
  size_t n;
  unsigned char lo = 0x80, hi = 0xbf;  // the second byte's range
  if (c >= 0xc2 && c <= 0xdf) n = 2;
  else if (c == 0xe0) n = 3, lo = 0xa0;
  else if (c >= 0xe1 && c <= 0xec) n = 3;
  else if (c == 0xed) n = 3, hi = 0x9f;  // no surrogates
  else if (c >= 0xee && c <= 0xef) n = 3;
  else if (c == 0xf0) n = 4, lo = 0x90;
  else if (c >= 0xf1 && c <= 0xf3) n = 4;
  else if (c == 0xf4) n = 4, hi = 0x8f;  // nothing past U+10FFFF
  else return 0;
  if (left < n || p[1] < lo || p[1] > hi) return 0;
  for (size_t i = 2; i < n; ++i)
    if ((p[i] & 0xc0) != 0x80) return 0;
  return n;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower((unsigned char)c));
  return s;
}

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 5 && s.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

bool valid_utf8(const std::string& s) {
  auto* p = reinterpret_cast<const unsigned char*>(s.data());
  for (size_t i = 0; i < s.size();) {
    size_t n = sequence_length(p + i, s.size() - i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::string to_valid_utf8(const std::string& s) {
  if (valid_utf8(s)) return s;
  auto* p = reinterpret_cast<const unsigned char*>(s.data());
  std::string out;
  out.reserve(s.size() + 8);
  for (size_t i = 0; i < s.size();) {
    size_t n = sequence_length(p + i, s.size() - i);
    if (n == 0) {
      out += "\xef\xbf\xbd";  // U+FFFD REPLACEMENT CHARACTER, one per bad byte
      ++i;
    } else {
      out.append(s, i, n);
      i += n;
    }
  }
  return out;
}

std::string clip_utf8(const std::string& s, size_t max_bytes) {
  if (s.size() <= max_bytes) return s;
  size_t cut = max_bytes;
  // Back to the start of the character the cut falls in (a UTF-8 character has at most 3
  // continuation bytes; in text that is not UTF-8 the caller repairs what is left).
  for (int i = 0; i < 3 && cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xc0) == 0x80; ++i) --cut;
  return s.substr(0, cut) + "...";
}

std::string media_type(const std::string& content_type) {
  std::string t = lower(trim(content_type.substr(0, content_type.find(';'))));
  size_t slash = t.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == t.size() || t.find('/', slash + 1) != std::string::npos)
    return "";
  for (char c : t)  // RFC 9110 token characters, and the slash
    if (!(std::isalnum((unsigned char)c) || std::strchr("!#$%&'*+-.^_`|~/", c))) return "";
  return t;
}

bool split_host(const std::string& host_header, std::string& host, std::string& port) {
  std::string h = lower(trim(host_header));
  host.clear();
  port.clear();
  if (h.empty()) return false;
  if (h[0] == '[') {  // an IPv6 literal
    size_t close = h.find(']');
    if (close == std::string::npos) return false;
    host = h.substr(1, close - 1);
    std::string rest = h.substr(close + 1);
    if (!rest.empty()) {
      if (rest[0] != ':' || !all_digits(rest.substr(1))) return false;
      port = rest.substr(1);
    }
    in6_addr a6;
    return inet_pton(AF_INET6, host.c_str(), &a6) == 1;
  }
  size_t colon = h.find(':');
  host = h.substr(0, colon);
  if (colon != std::string::npos) {
    port = h.substr(colon + 1);
    if (!all_digits(port)) return false;
  }
  if (!host.empty() && host.back() == '.') host.pop_back();  // "localhost." is localhost
  if (host.empty() || host.size() > 253) return false;
  for (char c : host)
    if (!(std::isalnum((unsigned char)c) || c == '-' || c == '.' || c == '_')) return false;
  return true;
}

bool is_loopback_host(const std::string& host) {
  std::string h = lower(host);
  if (h == "localhost" || (h.size() > 10 && h.compare(h.size() - 10, 10, ".localhost") == 0)) return true;
  in_addr a4;
  if (inet_pton(AF_INET, h.c_str(), &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
  in6_addr a6;
  if (inet_pton(AF_INET6, h.c_str(), &a6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&a6)) return true;
    if (IN6_IS_ADDR_V4MAPPED(&a6)) return a6.s6_addr[12] == 127;
  }
  return false;
}

bool HostPolicy::allows(const std::string& host_header) const {
  if (host_header.empty()) return true;  // HTTP/1.0 without Host: no browser sends that
  std::string host, port;
  if (!split_host(host_header, host, port)) return false;
  if (std::find(allowed.begin(), allowed.end(), host) != allowed.end()) return true;
  if (!loopback_only && allowed.empty()) return true;
  return is_loopback_host(host);
}

bool cross_site_request(const std::string& origin, const std::string& sec_fetch_site, const std::string& host_header) {
  if (lower(trim(sec_fetch_site)) == "cross-site") return true;
  std::string o = lower(trim(origin));
  if (o.empty()) return false;
  size_t sep = o.find("://");
  if (sep == std::string::npos) return true;  // "null" (a sandboxed or file: page) and anything malformed
  std::string scheme = o.substr(0, sep), rest = o.substr(sep + 3);
  if (rest.find('/') != std::string::npos) return true;  // an Origin has no path
  std::string ohost, oport, hhost, hport;
  if (!split_host(rest, ohost, oport) || !split_host(host_header, hhost, hport)) return true;
  std::string default_port = scheme == "https" ? "443" : "80";
  if (oport.empty()) oport = default_port;
  if (hport.empty()) hport = default_port;
  return ohost != hhost || std::stoi(oport) != std::stoi(hport);
}

int count_ranges(const std::string& range_header) {
  std::string r = lower(trim(range_header));
  if (r.compare(0, 6, "bytes=") != 0) return 0;
  return int(std::count(r.begin(), r.end(), ',')) + 1;
}

}  // namespace srv
