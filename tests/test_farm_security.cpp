// The farm's credentials and signatures (server/farm_security.h, server/redis_client.h): queue URLs
// with users, passwords and databases; the password's sources; HMAC-SHA256 over length-prefixed
// fields; the loopback rule for unsigned farms.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "farm_security.h"
#include "redis_client.h"

namespace {

using srv::FarmKey;
using srv::RedisAddress;

std::string temp_file(const std::string& name, const std::string& text) {
  std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  chmod(path.c_str(), 0600);
  return path;
}

TEST(FarmSecurity, ParsesUsersPasswordsAndDatabases) {
  RedisAddress a = RedisAddress::parse("redis://render-worker:p%40ss:w0rd@192.0.2.1:6380/3");
  EXPECT_EQ(a.user, "render-worker");
  EXPECT_EQ(a.password, "p@ss:w0rd");  // percent-decoded; the first ':' splits user from password
  EXPECT_EQ(a.host, "192.0.2.1");
  EXPECT_EQ(a.port, 6380);
  EXPECT_EQ(a.db, 3);
  EXPECT_EQ(a.url(), "redis://render-worker@192.0.2.1:6380/3");  // never the password
  RedisAddress b = RedisAddress::parse("redis://:secret@localhost");
  EXPECT_EQ(b.user, "");
  EXPECT_EQ(b.password, "secret");
  EXPECT_EQ(b.port, 6379);
  EXPECT_EQ(b.url(), "redis://localhost:6379");
  EXPECT_EQ(RedisAddress::parse("redis://127.0.0.1:6379/").db, 0);
}

TEST(FarmSecurity, BadUrlsAreRefusedWithoutShowingThePassword) {
  for (const char* url : {"redis://u:secret@host:0", "redis://u:secret@host:6379/x", "redis://u:secret@:6379",
                          "redis://u:sec%zzret@host", "http://u:secret@host"}) {
    try {
      RedisAddress::parse(url);
      ADD_FAILURE() << url << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).find("secret"), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find("sec%zzret"), std::string::npos) << e.what();
    }
  }
}

TEST(FarmSecurity, PasswordFromFileEnvironmentOrUrl) {
  srv::FarmOptions opts;
  opts.password_file = temp_file("pw", "from-file\n");
  EXPECT_EQ(srv::farm_address("redis://127.0.0.1:1", opts, "test").password, "from-file");  // newline dropped
  EXPECT_THROW(srv::farm_address("redis://:x@127.0.0.1:1", opts, "test"), std::invalid_argument);  // given twice
  opts.password_file = temp_file("empty", "\n");
  EXPECT_THROW(srv::farm_address("redis://127.0.0.1:1", opts, "test"), std::invalid_argument);
  opts.password_file = ::testing::TempDir() + "no-such-file";
  EXPECT_THROW(srv::farm_address("redis://127.0.0.1:1", opts, "test"), std::invalid_argument);
  opts.password_file.clear();
  setenv("PT_REDIS_PASSWORD", "from-env", 1);
  EXPECT_EQ(srv::farm_address("redis://127.0.0.1:1", opts, "test").password, "from-env");
  EXPECT_EQ(srv::farm_address("redis://:in-url@127.0.0.1:1", opts, "test").password, "in-url");
  unsetenv("PT_REDIS_PASSWORD");
  EXPECT_EQ(srv::farm_address("redis://127.0.0.1:1", opts, "test").password, "");
}

TEST(FarmSecurity, SignaturesBindEveryFieldAndItsBoundaries) {
  FarmKey key("0123456789abcdef-key");
  const std::string sig = key.sign({"pt-result", "job", "run", "7", "w1", "bytes"});
  EXPECT_EQ(sig.size(), 64u);
  EXPECT_EQ(sig, key.sign({"pt-result", "job", "run", "7", "w1", "bytes"}));
  EXPECT_TRUE(key.verify(sig, {"pt-result", "job", "run", "7", "w1", "bytes"}));
  EXPECT_FALSE(key.verify(sig, {"pt-result", "job", "run", "8", "w1", "bytes"}));
  EXPECT_FALSE(key.verify(sig, {"pt-result", "jobr", "un", "7", "w1", "bytes"}));  // moved boundary
  EXPECT_FALSE(key.verify(sig, {"pt-error", "job", "run", "7", "w1", "bytes"}));
  EXPECT_FALSE(key.verify(sig.substr(0, 63), {"pt-result", "job", "run", "7", "w1", "bytes"}));
  EXPECT_FALSE(FarmKey("another-key-0123456").verify(sig, {"pt-result", "job", "run", "7", "w1", "bytes"}));
  // HMAC-SHA256 (RFC 4231 test case 2's key and data) over the length-prefixed field, as the
  // Python tests compute it: hmac.new(b"Jefe", struct.pack("<Q", 28) + data, sha256).
  EXPECT_EQ(FarmKey("Jefe").sign({"what do ya want for nothing?"}),
            "c0b77cf99718fc7f09c8727ff74305bde25761b2db20b1081cfcc82a3ec6029e");
  EXPECT_EQ(srv::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(FarmSecurity, KeysAreReadAndCheckedForLength) {
  EXPECT_THROW(FarmKey::load(temp_file("short.key", "too short\n")), std::invalid_argument);
  auto key = FarmKey::load(temp_file("good.key", "0123456789abcdef0123\n"));
  EXPECT_EQ(key->sign({"x"}), FarmKey("0123456789abcdef0123").sign({"x"}));
}

TEST(FarmSecurity, UnsignedFarmsStayOnLoopback) {
  EXPECT_TRUE(srv::resolves_to_loopback("127.0.0.1"));
  EXPECT_TRUE(srv::resolves_to_loopback("localhost"));
  EXPECT_TRUE(srv::resolves_to_loopback("::1"));
  EXPECT_FALSE(srv::resolves_to_loopback("192.0.2.1"));
  srv::FarmOptions opts;
  EXPECT_EQ(srv::farm_key(RedisAddress::parse("redis://127.0.0.1:1"), opts, "test"), nullptr);
  EXPECT_THROW(srv::farm_key(RedisAddress::parse("redis://192.0.2.1:1"), opts, "test"), std::invalid_argument);
  opts.insecure = true;
  EXPECT_EQ(srv::farm_key(RedisAddress::parse("redis://192.0.2.1:1"), opts, "test"), nullptr);
  opts.key_file = temp_file("farm.key", "0123456789abcdef0123");
  EXPECT_NE(srv::farm_key(RedisAddress::parse("redis://192.0.2.1:1"), opts, "test"), nullptr);
}

}  // namespace
