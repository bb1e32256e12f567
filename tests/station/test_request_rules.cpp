// Issue 19 items 7 and 9: the rules a request head must pass before httplib reads it, and the
// Host forms that read without the token (the end-to-end attacks: tests/web/api_limits_test.py).
#include <gtest/gtest.h>

#include "station/http/request_rules.hpp"

namespace sh = station::http;

namespace {
int verdict(const std::string& fields) {
  return sh::check_request_head("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n" + fields + "\r\n", {})
      .status;
}
}  // namespace

TEST(RequestRules, AHeadEndsAtItsEmptyLineWithCrlfOrBareLf) {
  EXPECT_EQ(sh::head_end("GET / HTTP/1.1\r\nHost: x\r\n\r\nbody"), 27u);
  EXPECT_EQ(sh::head_end("GET / HTTP/1.1\nHost: x\n\nbody"), 24u);
  EXPECT_FALSE(sh::head_end("GET / HTTP/1.1\r\nHost: x\r\n"));
}

TEST(RequestRules, MalformedFieldsAre400AndTooManyAre431) {
  EXPECT_EQ(verdict("X-A: a\r\n"), 0);
  EXPECT_EQ(verdict("Content-Length: 5\r\nContent-Length: 5\r\n"), 0);  // RFC 9110 8.6
  EXPECT_EQ(verdict("Content-Length: 5, 5\r\n"), 0);
  EXPECT_EQ(verdict("X-No-Colon a\r\n"), 400);
  EXPECT_EQ(verdict("X-A: a\r\n folded\r\n"), 400);
  EXPECT_EQ(verdict("X-A : a\r\n"), 400);
  EXPECT_EQ(verdict(": a\r\n"), 400);
  EXPECT_EQ(verdict("Content-Length: 5\r\nContent-Length: 6\r\n"), 400);
  EXPECT_EQ(verdict("Content-Length: 5, 6\r\n"), 400);
  EXPECT_EQ(verdict("Content-Length: -1\r\n"), 400);
  EXPECT_EQ(verdict("Content-Length: 1\r\nTransfer-Encoding: chunked\r\n"), 400);
  EXPECT_EQ(verdict("Host: evil.com\r\n"), 400);
  EXPECT_EQ(verdict(std::string("X-A: a\0b\r\n", 10)), 400);
  EXPECT_EQ(verdict("X-A: a\rb\r\n"), 400);
  std::string fields;
  for (int i = 0; i < 99; ++i) fields += "X-" + std::to_string(i) + ": a\r\n";
  EXPECT_EQ(verdict(fields), 0);  // 100 with Host
  EXPECT_EQ(verdict(fields + "X-Last: a\r\n"), 431);
}

TEST(RequestRules, AnOversizedHeadIs414WithoutALineElse431) {
  const sh::HeadLimits limits;
  EXPECT_EQ(sh::oversized_head(std::string(9000, 'a'), limits).status, 414);
  EXPECT_EQ(sh::oversized_head("GET / HTTP/1.1\r\n" + std::string(9000, 'a'), limits).status, 431);
}

TEST(RequestRules, OnlyLoopbackLiteralsAndLocalhostAreLoopbackHosts) {
  for (const char* h : {"127.0.0.1", "127.0.0.1:8080", "127.1.2.3", "[::1]", "[::1]:80",
                        "[::ffff:127.0.0.1]:1", "localhost", "LocalHost:8080"})
    EXPECT_TRUE(sh::loopback_host(h)) << h;
  for (const char* h : {"127.evil.com", "127.0.0.1.nip.io:8080", "0x7f.1", "127.1", "2130706433",
                        "localhost.evil.com", "[::1].evil.com", "[::2]", "127.0.0.1:80x",
                        "127.0.0.1:123456", "10.0.0.1", "", "[::1", "::1"})
    EXPECT_FALSE(sh::loopback_host(h)) << h;
  // inet_pton reads up to a NUL: the rest of the name must not be dropped (fuzz finding).
  using namespace std::string_view_literals;
  EXPECT_FALSE(sh::loopback_host("127.0.0.1\0.evil.com"sv));
  EXPECT_FALSE(sh::loopback_host("[::1\0\0]:80"sv));
}
