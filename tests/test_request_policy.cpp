// The request parts the server interprets itself (server/request_policy.h), against cases worked
// out by hand: UTF-8 per RFC 3629, media types per RFC 9110, Host names a loopback server answers,
// cross-site detection, range counting. The scene loader's clipping keeps UTF-8 whole too.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "collada.h"
#include "request_policy.h"

using namespace srv;

TEST(Utf8, AcceptsWellFormedAndRefusesEachIllFormedKind) {
  EXPECT_TRUE(valid_utf8(""));
  EXPECT_TRUE(valid_utf8("plain ascii"));
  EXPECT_TRUE(valid_utf8("\xc3\xa9t\xc3\xa9"));          // été
  EXPECT_TRUE(valid_utf8("\xe5\xba\x8a"));               // 床
  EXPECT_TRUE(valid_utf8("\xf0\x9f\x98\x80"));           // U+1F600
  EXPECT_TRUE(valid_utf8("\xf4\x8f\xbf\xbf"));           // U+10FFFF, the last code point
  EXPECT_FALSE(valid_utf8("\xe9t\xe9"));                 // Latin-1
  EXPECT_FALSE(valid_utf8("\xc0\xaf"));                  // overlong '/'
  EXPECT_FALSE(valid_utf8("\xe0\x80\xaf"));              // overlong, three bytes
  EXPECT_FALSE(valid_utf8("\xed\xa0\x80"));              // a surrogate, U+D800
  EXPECT_FALSE(valid_utf8("\xf4\x90\x80\x80"));          // past U+10FFFF
  EXPECT_FALSE(valid_utf8("\xe5\xba"));                  // cut short
  EXPECT_FALSE(valid_utf8("\x80"));                      // a lone continuation byte
  EXPECT_FALSE(valid_utf8("\xff"));
}

TEST(Utf8, RepairReplacesEachBadByteAndKeepsTheRest) {
  EXPECT_EQ(to_valid_utf8("sol-\xe9t\xe9"), "sol-\xef\xbf\xbdt\xef\xbf\xbd");
  EXPECT_EQ(to_valid_utf8("a\xe5\xba"), "a\xef\xbf\xbd\xef\xbf\xbd");
  EXPECT_EQ(to_valid_utf8("\xe5\xba\x8a ok"), "\xe5\xba\x8a ok");
}

TEST(Utf8, ClippingNeverSplitsACharacter) {
  std::string name = "x";
  for (int i = 0; i < 30; ++i) name += "\xe5\xba\x8a";  // 91 bytes
  std::string c = clip_utf8(name, 60);  // byte 60 is inside the 20th character
  EXPECT_EQ(c.size(), 58u + 3u);        // "x" + 19 characters + "..."
  EXPECT_TRUE(valid_utf8(c));
  EXPECT_EQ(clip_utf8("short", 60), "short");
}

TEST(Utf8, SceneErrorsQuoteLongMultibyteNamesWhole) {
  std::ifstream in(std::string(PT_OWN_SCENES) + "/cornell.dae");
  std::stringstream text;
  text << in.rdbuf();
  std::string dae = text.str(), id = "x";
  for (int i = 0; i < 30; ++i) id += "\xe5\xba\x8a";  // 91 bytes: the loader's 60-byte clip falls inside one
  auto swap = [&](const std::string& from, const std::string& to) {
    size_t at = dae.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    dae.replace(at, from.size(), to);
  };
  swap("id=\"floor-mesh-positions-array\" count=\"12\"", "id=\"" + id + "\" count=\"13\"");
  swap("#floor-mesh-positions-array", "#" + id);
  try {
    pt::parse_collada(dae, "odd.dae");
    FAIL() << "a count that disagrees with the data must fail";
  } catch (const pt::SceneError& e) {
    EXPECT_TRUE(valid_utf8(e.what())) << e.what();
    EXPECT_NE(std::string(e.what()).find("count says 13"), std::string::npos) << e.what();
  }
}

TEST(MediaType, IsTheLowerCaseTypeWithoutParameters) {
  EXPECT_EQ(media_type("application/json"), "application/json");
  EXPECT_EQ(media_type(" Application/JSON ; charset=utf-8"), "application/json");
  EXPECT_EQ(media_type("text/plain; x=application/json"), "text/plain");
  EXPECT_EQ(media_type(""), "");
  EXPECT_EQ(media_type("json"), "");
  EXPECT_EQ(media_type("application/"), "");
  EXPECT_EQ(media_type("a/b/c"), "");
  EXPECT_EQ(media_type("application/json\x01"), "");
}

TEST(Host, SplitsNamesAddressesAndPorts) {
  std::string h, p;
  ASSERT_TRUE(split_host("LocalHost:8080", h, p));
  EXPECT_EQ(h, "localhost");
  EXPECT_EQ(p, "8080");
  ASSERT_TRUE(split_host("[::1]:80", h, p));
  EXPECT_EQ(h, "::1");
  ASSERT_TRUE(split_host("localhost.", h, p));
  EXPECT_EQ(h, "localhost");
  EXPECT_FALSE(split_host("", h, p));
  EXPECT_FALSE(split_host("a b", h, p));
  EXPECT_FALSE(split_host("host:80x", h, p));
  EXPECT_FALSE(split_host("[::1", h, p));
  EXPECT_FALSE(split_host("[zz]:1", h, p));
}

TEST(Host, ALoopbackServerAnswersLoopbackNamesAndAllowedOnes) {
  HostPolicy loopback;
  loopback.allowed = {"render.example.org"};
  for (const char* ok : {"localhost", "localhost:1", "app.localhost", "127.0.0.1", "127.255.0.9:80", "[::1]:8080",
                         "[::ffff:127.0.0.1]", "render.example.org:443", ""})
    EXPECT_TRUE(loopback.allows(ok)) << ok;
  for (const char* bad : {"evil.example", "127.0.0.1.evil.example", "localhost.evil.example", "128.0.0.1",
                          "10.0.0.1:80", "[::2]", "[::ffff:10.0.0.1]", "a b"})
    EXPECT_FALSE(loopback.allows(bad)) << bad;
  HostPolicy open;
  open.loopback_only = false;
  EXPECT_TRUE(open.allows("evil.example"));  // bound to the network, no --allowed-host: any name
  open.allowed = {"render.example.org"};
  EXPECT_FALSE(open.allows("evil.example"));
  EXPECT_TRUE(open.allows("render.example.org"));
}

TEST(CrossSite, ComparesTheOriginWithTheHostItWasSentTo) {
  EXPECT_FALSE(cross_site_request("", "", "127.0.0.1:8080"));  // curl, scripts
  EXPECT_FALSE(cross_site_request("http://127.0.0.1:8080", "same-origin", "127.0.0.1:8080"));
  EXPECT_FALSE(cross_site_request("http://localhost", "", "localhost:80"));  // default port
  EXPECT_TRUE(cross_site_request("https://localhost", "", "localhost:80"));  // 443 is another port
  EXPECT_TRUE(cross_site_request("", "cross-site", "127.0.0.1:8080"));
  EXPECT_TRUE(cross_site_request("null", "", "127.0.0.1:8080"));
  EXPECT_TRUE(cross_site_request("http://evil.example", "", "127.0.0.1:8080"));
  EXPECT_TRUE(cross_site_request("http://127.0.0.1:8081", "", "127.0.0.1:8080"));
  EXPECT_TRUE(cross_site_request("http://127.0.0.1:8080/path", "", "127.0.0.1:8080"));
}

TEST(Ranges, AreCountedOnlyInAByteRangeHeader) {
  EXPECT_EQ(count_ranges(""), 0);
  EXPECT_EQ(count_ranges("items=0-1"), 0);
  EXPECT_EQ(count_ranges("bytes=0-99"), 1);
  EXPECT_EQ(count_ranges("Bytes=0-, 5-9"), 2);
  EXPECT_EQ(count_ranges("bytes=" + std::string(999, ',')), 1000);
}
