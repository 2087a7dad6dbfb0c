#include "farm_security.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "request_policy.h"

namespace srv {

namespace {

std::string to_hex(const unsigned char* bytes, size_t n) {
  static const char digits[] = "0123456789abcdef";
  std::string out(2 * n, '0');
  for (size_t i = 0; i < n; ++i) out[2 * i] = digits[bytes[i] >> 4], out[2 * i + 1] = digits[bytes[i] & 15];
  return out;
}

// A secret file's bytes, trailing white space (an editor's newline) dropped; at most 1 MiB.
std::string read_secret(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(std::string(what) + " '" + path + "' cannot be read");
  std::ostringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  if (s.size() > (1u << 20)) throw std::invalid_argument(std::string(what) + " '" + path + "' is larger than 1 MiB");
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
  struct stat st {};
  if (stat(path.c_str(), &st) == 0 && (st.st_mode & 077))
    std::fprintf(stderr, "warning: %s '%s' may be read by other users (chmod 600 it)\n", what, path.c_str());
  return s;
}

}  // namespace

struct FarmKey::Mac {
  EVP_MAC* mac = nullptr;
};

FarmKey::FarmKey(std::string secret) : m_secret(std::move(secret)), m_mac(std::make_unique<Mac>()) {
  m_mac->mac = EVP_MAC_fetch(nullptr, "HMAC", nullptr);
  if (!m_mac->mac) throw std::runtime_error("OpenSSL has no HMAC");
}

FarmKey::~FarmKey() { EVP_MAC_free(m_mac->mac); }

std::shared_ptr<const FarmKey> FarmKey::load(const std::string& path) {
  std::string secret = read_secret(path, "the farm key file");
  if (secret.size() < kMinBytes)
    throw std::invalid_argument("the farm key file '" + path + "' holds " + std::to_string(secret.size()) +
                                " bytes; a key needs at least " + std::to_string(kMinBytes) +
                                " (make one with: head -c 32 /dev/urandom | base64 > farm.key)");
  return std::make_shared<const FarmKey>(std::move(secret));
}

std::string FarmKey::sign(std::initializer_list<std::string_view> fields) const {
  EVP_MAC_CTX* ctx = EVP_MAC_CTX_new(m_mac->mac);
  char digest[] = "SHA256";
  OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digest, 0), OSSL_PARAM_construct_end()};
  bool ok = ctx && EVP_MAC_init(ctx, reinterpret_cast<const unsigned char*>(m_secret.data()), m_secret.size(), params);
  for (std::string_view f : fields) {
    unsigned char len[8];
    for (int i = 0; i < 8; ++i) len[i] = static_cast<unsigned char>(uint64_t(f.size()) >> (8 * i));
    ok = ok && EVP_MAC_update(ctx, len, sizeof len) &&
         EVP_MAC_update(ctx, reinterpret_cast<const unsigned char*>(f.data()), f.size());
  }
  unsigned char out[EVP_MAX_MD_SIZE];
  size_t n = 0;
  ok = ok && EVP_MAC_final(ctx, out, &n, sizeof out);
  EVP_MAC_CTX_free(ctx);
  if (!ok || n != 32) throw std::runtime_error("OpenSSL's HMAC-SHA256 failed");
  return to_hex(out, n);
}

bool FarmKey::verify(std::string_view signature, std::initializer_list<std::string_view> fields) const {
  return same_signature(signature, sign(fields));
}

bool same_signature(std::string_view a, std::string_view b) {
  return a.size() == b.size() && CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

std::string sha256_hex(std::string_view bytes) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (!EVP_Digest(bytes.data(), bytes.size(), md, &n, EVP_sha256(), nullptr)) throw std::runtime_error("OpenSSL's SHA-256 failed");
  return to_hex(md, n);
}

bool resolves_to_loopback(const std::string& host) {
  if (is_loopback_host(host)) return true;  // request_policy.h: the literal forms
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* list = nullptr;
  if (getaddrinfo(host.c_str(), nullptr, &hints, &list) != 0 || !list) return false;
  bool all = true;
  for (addrinfo* a = list; a; a = a->ai_next) {
    if (a->ai_family == AF_INET) {
      const uint32_t ip = ntohl(reinterpret_cast<const sockaddr_in*>(a->ai_addr)->sin_addr.s_addr);
      all = all && (ip >> 24) == 127;
    } else if (a->ai_family == AF_INET6) {
      const in6_addr& ip = reinterpret_cast<const sockaddr_in6*>(a->ai_addr)->sin6_addr;
      all = all && (IN6_IS_ADDR_LOOPBACK(&ip) || (IN6_IS_ADDR_V4MAPPED(&ip) && ip.s6_addr[12] == 127));
    } else {
      all = false;
    }
  }
  freeaddrinfo(list);
  return all;
}

RedisAddress farm_address(const std::string& url, const FarmOptions& options, const char* who) {
  RedisAddress a = RedisAddress::parse(url);
  if (!options.password_file.empty()) {
    if (!a.password.empty())
      throw std::invalid_argument("the Redis password is given twice: in the queue URL and in --redis-password-file");
    a.password = read_secret(options.password_file, "the Redis password file");
    if (a.password.empty()) throw std::invalid_argument("the Redis password file '" + options.password_file + "' is empty");
  } else if (!a.password.empty()) {
    std::fprintf(stderr, "%s: warning: the queue URL holds the Redis password, which other users see in the process "
                 "list; use --redis-password-file or PT_REDIS_PASSWORD instead\n", who);
  } else if (const char* env = std::getenv("PT_REDIS_PASSWORD"); env && *env) {
    a.password = env;
  }
  return a;
}

std::shared_ptr<const FarmKey> farm_key(const RedisAddress& address, const FarmOptions& options, const char* who) {
  std::shared_ptr<const FarmKey> key = options.key_file.empty() ? nullptr : FarmKey::load(options.key_file);
  const bool loopback = resolves_to_loopback(address.host);
  if (!key && !loopback && !options.insecure)
    throw std::invalid_argument(
        "Redis at " + address.url() + " is not on loopback and passes are not signed: anyone who can write to that "
        "Redis could paint pixels into renders, fail or stall jobs, and hand workers scenes to render. Give the "
        "server and every worker the same --farm-key-file (docs/scale-out.md, \"Security\"), or --insecure-farm "
        "to run unsigned anyway on a network you trust completely");
  if (!key && !loopback)
    std::fprintf(stderr, "%s: warning: --insecure-farm: passes to and from %s are not signed; anyone who can write to "
                 "that Redis can change renders and fail jobs\n", who, address.url().c_str());
  if (key && !loopback && address.password.empty())
    std::fprintf(stderr, "%s: warning: Redis at %s takes no password: passes are signed, but anyone who reaches it can "
                 "delete the farm's keys and stall jobs (docs/scale-out.md gives the ACL rules)\n", who,
                 address.url().c_str());
  return key;
}

}  // namespace srv
