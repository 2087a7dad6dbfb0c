// What keeps a render farm safe once Redis leaves loopback (docs/scale-out.md, "Security"):
// the Redis password kept out of the process list, a shared farm key that signs every pass request
// and every pass result (HMAC-SHA256, RFC 2104), and the rule that an unsigned farm stays on
// loopback unless its owner says --insecure-farm.
#pragma once

#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>

#include "redis_client.h"

namespace srv {

// The farm key: bytes read from --farm-key-file, the same file on the server and every worker.
class FarmKey {
 public:
  // Reads the key (trailing white space dropped); throws std::invalid_argument naming the file when
  // it cannot be read or holds fewer than kMinBytes bytes. Warns when others may read it.
  static std::shared_ptr<const FarmKey> load(const std::string& path);
  explicit FarmKey(std::string secret);
  ~FarmKey();
  FarmKey(const FarmKey&) = delete;
  FarmKey& operator=(const FarmKey&) = delete;
  static constexpr size_t kMinBytes = 16;

  // HMAC-SHA256 of the fields as 64 hex digits. Each field is length-prefixed, so no two different
  // field lists sign the same bytes. The first field names the message's kind ("pt-pass", ...).
  std::string sign(std::initializer_list<std::string_view> fields) const;
  // Whether `signature` is the fields' signature (compared in constant time).
  bool verify(std::string_view signature, std::initializer_list<std::string_view> fields) const;

 private:
  struct Mac;
  std::string m_secret;
  std::unique_ptr<Mac> m_mac;
};

// Whether two signatures are the same, compared in constant time (no timing tells how much matched).
bool same_signature(std::string_view a, std::string_view b);

// SHA-256 of `bytes` as 64 hex digits: a scene's content name in Redis, which a signed run covers.
std::string sha256_hex(std::string_view bytes);

// Whether every address `host` resolves to is a loopback one (127.0.0.0/8, ::1). A name that does
// not resolve counts as not loopback.
bool resolves_to_loopback(const std::string& host);

// The farm's security settings, from the command line of render-server --queue or render-worker.
struct FarmOptions {
  std::string password_file;  // --redis-password-file
  std::string key_file;       // --farm-key-file
  bool insecure = false;      // --insecure-farm
};

// The Redis address of `url` with its password taken from --redis-password-file, else from the
// environment variable PT_REDIS_PASSWORD, else from the URL (which shows it in the process list:
// warned about). Throws std::invalid_argument naming the URL or the file.
RedisAddress farm_address(const std::string& url, const FarmOptions& options, const char* who);

// The farm key, or null when none is set; refuses (std::invalid_argument, explaining the risk) an
// unsigned farm on a Redis that is not on loopback unless --insecure-farm is given, and warns about
// what remains exposed (no password, --insecure-farm).
std::shared_ptr<const FarmKey> farm_key(const RedisAddress& address, const FarmOptions& options, const char* who);

}  // namespace srv
