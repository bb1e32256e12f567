// The API token file: created 0600 with 256 random bits, read back; anything another user or
// process could have placed or read is refused with one line naming the file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "station/common/input_error.hpp"
#include "station/http/token.hpp"

namespace station::http {
namespace {

namespace fs = std::filesystem;

class TokenFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fs::path("token-test-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const char* name) const { return (dir_ / name).string(); }
  static void write(const std::string& p, const std::string& text, mode_t mode) {
    std::ofstream(p) << text;
    ::chmod(p.c_str(), mode);
  }
  static std::string refusal(const std::string& p) {
    try {
      load_or_create_token(p);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(TokenFile, IsCreated0600WithA256BitTokenAndReadBackTheSame) {
  const auto p = path("api.token");
  const std::string token = load_or_create_token(p);
  EXPECT_EQ(token.size(), 64u);  // 32 random bytes as hex
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(load_or_create_token(p), token);
  EXPECT_NE(load_or_create_token(path("other.token")), token);
  EXPECT_TRUE(fs::is_empty(dir_) == false);
  for (const auto& e : fs::directory_iterator(dir_))  // no temporary left behind
    EXPECT_EQ(e.path().extension(), ".token") << e.path();
}

TEST_F(TokenFile, RefusesWhatOthersCouldReadOrPlace) {
  const std::string good(40, 'a');
  write(path("wide"), good, 0644);
  EXPECT_NE(refusal(path("wide")).find("readable by others"), std::string::npos);
  write(path("short"), "abc", 0600);
  EXPECT_NE(refusal(path("short")).find(">= 32"), std::string::npos);
  write(path("key"), "-----BEGIN OPENSSH PRIVATE KEY-----\n", 0600);
  EXPECT_NE(refusal(path("key")).find(">= 32"), std::string::npos);
  write(path("target"), good, 0600);
  fs::create_symlink(path("target"), path("link"));
  EXPECT_NE(refusal(path("link")).find("symbolic link"), std::string::npos);
  fs::create_directories(path("dir"));
  EXPECT_NE(refusal(path("dir")).find("not a regular file"), std::string::npos);
  EXPECT_NE(refusal(path("no/such/dir/token")).find("no/such/dir/token"), std::string::npos);
  EXPECT_EQ(load_or_create_token(path("target")), good);
}

TEST(Bearer, MatchesOnlyTheExactHeader) {
  const std::string t(40, 'x');
  EXPECT_TRUE(bearer_matches("Bearer " + t, t));
  EXPECT_FALSE(bearer_matches("Bearer " + t + "x", t));
  EXPECT_FALSE(bearer_matches("bearer " + t, t));
  EXPECT_FALSE(bearer_matches("Basic " + t, t));
  EXPECT_FALSE(bearer_matches("Bearer " + std::string(40, 'y'), t));
  EXPECT_FALSE(bearer_matches("", t));
}

}  // namespace
}  // namespace station::http
