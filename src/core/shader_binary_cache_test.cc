#include "core/shader_binary_cache.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/scoped_env.h"

namespace sffd {
namespace {

namespace fs = std::filesystem;

using test::ScopedEnv;

class ShaderBinaryCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sffd-cache-test-" + std::to_string(::getpid()) + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }
  static std::vector<uint8_t> bytes(size_t n, uint8_t seed) {
    std::vector<uint8_t> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = uint8_t(seed + i * 7);
    return v;
  }
  fs::path dir_;
};

TEST_F(ShaderBinaryCacheTest, GivesBackWhatWasStoredUnderItsKeyOnly) {
  ShaderBinaryCache cache(dir_ / "nested" / "folder");   // made on the first store
  EXPECT_FALSE(cache.load("kernel a"));
  const std::vector<uint8_t> a = bytes(1000, 1), b = bytes(10, 2);
  ASSERT_TRUE(cache.store("kernel a", a));
  ASSERT_TRUE(cache.store("kernel b", b));
  EXPECT_EQ(cache.load("kernel a"), a);
  EXPECT_EQ(ShaderBinaryCache(cache.folder()).load("kernel b"), b);   // another cache object, as another process
  EXPECT_FALSE(cache.load("kernel c"));
  ASSERT_TRUE(cache.store("kernel a", b));   // replaced whole
  EXPECT_EQ(cache.load("kernel a"), b);
  EXPECT_TRUE(cache.store("empty", {}));
  EXPECT_EQ(cache.load("empty"), std::vector<uint8_t>{});
}

TEST_F(ShaderBinaryCacheTest, DamagedOrForeignFilesAreMisses) {
  ShaderBinaryCache cache(dir_);
  const std::vector<uint8_t> a = bytes(4000, 3);
  ASSERT_TRUE(cache.store("key", a));
  const fs::path file = cache.fileFor("key");
  std::string whole;
  {
    std::ifstream in(file, std::ios::binary);
    whole.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto write = [&](const std::string& s) {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << s;
  };
  write(whole.substr(0, whole.size() - 1));   // truncated
  EXPECT_FALSE(cache.load("key"));
  std::string flipped = whole;
  flipped[flipped.size() - 100] ^= 0x20;   // a bit of the binary changed
  write(flipped);
  EXPECT_FALSE(cache.load("key"));
  write(whole + "x");   // longer than it says
  EXPECT_FALSE(cache.load("key"));
  write("");
  EXPECT_FALSE(cache.load("key"));
  write(whole);
  EXPECT_EQ(cache.load("key"), a);
  // A file of another key under this key's name (a hash collision) is not this key's.
  fs::copy_file(file, cache.fileFor("other key"), fs::copy_options::overwrite_existing);
  EXPECT_FALSE(cache.load("other key"));
}

TEST_F(ShaderBinaryCacheTest, AFolderThatCannotBeWrittenIsOnlyACacheThatMisses) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "file") << "not a folder";
  ShaderBinaryCache underAFile(dir_ / "file" / "cache");
  EXPECT_FALSE(underAFile.store("key", bytes(10, 4)));
  EXPECT_FALSE(underAFile.load("key"));
  if (::geteuid() != 0) {   // root writes anywhere
    fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_FALSE(ShaderBinaryCache(dir_).store("key", bytes(10, 4)));
  }
}

TEST_F(ShaderBinaryCacheTest, KeepsToItsSizeDroppingTheLeastRecentlyUsed) {
  ShaderBinaryCache cache(dir_, 3500);   // room for three of these (1,000 bytes and a header each)
  ASSERT_TRUE(cache.store("a", bytes(1000, 1)));
  ASSERT_TRUE(cache.store("b", bytes(1000, 2)));
  ASSERT_TRUE(cache.store("c", bytes(1000, 3)));
  // File times may be coarse: set them apart so that the order is clear.
  const auto now = fs::file_time_type::clock::now();
  fs::last_write_time(cache.fileFor("a"), now - std::chrono::minutes(3));
  fs::last_write_time(cache.fileFor("b"), now - std::chrono::minutes(2));
  fs::last_write_time(cache.fileFor("c"), now - std::chrono::minutes(1));
  ASSERT_TRUE(cache.load("a"));   // used: now the newest
  ASSERT_TRUE(cache.store("d", bytes(1000, 4)));
  EXPECT_TRUE(cache.load("a"));
  EXPECT_FALSE(cache.load("b"));   // the least recently used went
  EXPECT_TRUE(cache.load("c"));
  EXPECT_TRUE(cache.load("d"));
  // A temporary file a dead writer left behind goes once it is an hour old; a fresh one stays.
  std::ofstream(dir_ / "0000000000000000.bin.tmp1-0") << "x";
  std::ofstream(dir_ / "0000000000000001.bin.tmp2-0") << "x";
  fs::last_write_time(dir_ / "0000000000000000.bin.tmp1-0", now - std::chrono::hours(2));
  ASSERT_TRUE(cache.store("e", bytes(10, 5)));
  EXPECT_FALSE(fs::exists(dir_ / "0000000000000000.bin.tmp1-0"));
  EXPECT_TRUE(fs::exists(dir_ / "0000000000000001.bin.tmp2-0"));
}

TEST_F(ShaderBinaryCacheTest, WritersInParallelLeaveWholeFiles) {
  ShaderBinaryCache cache(dir_);
  std::vector<std::thread> writers;
  for (int t = 0; t < 4; ++t)
    writers.emplace_back([&, t] {
      for (int i = 0; i < 20; ++i) cache.store("shared", bytes(20000, uint8_t(t)));
    });
  for (std::thread& w : writers) w.join();
  std::optional<std::vector<uint8_t>> got = cache.load("shared");
  ASSERT_TRUE(got);
  bool someWriters = false;
  for (int t = 0; t < 4; ++t) someWriters = someWriters || *got == bytes(20000, uint8_t(t));
  EXPECT_TRUE(someWriters);
  for (const fs::directory_entry& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().extension(), ".bin") << e.path();   // no temporary file left
}

TEST_F(ShaderBinaryCacheTest, CountsHitsMissesAndStores) {
  ShaderBinaryCache cache(dir_);
  const ShaderBinaryCache::Counts before = ShaderBinaryCache::counts();
  cache.load("x");
  cache.store("x", bytes(5, 1));
  cache.load("x");
  const ShaderBinaryCache::Counts after = ShaderBinaryCache::counts();
  EXPECT_EQ(after.misses - before.misses, 1u);
  EXPECT_EQ(after.stores - before.stores, 1u);
  EXPECT_EQ(after.hits - before.hits, 1u);
}

TEST(ShaderCacheFolder, FollowsTheRequestThenTheEnvironment) {
  ScopedEnv disable("SFFD_SHADER_CACHE_DISABLE", nullptr), dir("SFFD_SHADER_CACHE_DIR", nullptr);
  ScopedEnv xdg("XDG_CACHE_HOME", "/x/cache"), home("HOME", "/home/u");
  EXPECT_EQ(shaderCacheFolder("none"), std::nullopt);
  EXPECT_EQ(shaderCacheFolder("/some/folder"), fs::path("/some/folder"));
  EXPECT_EQ(shaderCacheFolder(""), fs::path("/x/cache/sffd"));
  {
    ScopedEnv relative("XDG_CACHE_HOME", "relative");   // the XDG rule: ignored unless absolute
    EXPECT_EQ(shaderCacheFolder(""), fs::path("/home/u/.cache/sffd"));
  }
  {
    ScopedEnv noXdg("XDG_CACHE_HOME", nullptr), noHome("HOME", nullptr);
    EXPECT_EQ(shaderCacheFolder(""), std::nullopt);
  }
  ScopedEnv set("SFFD_SHADER_CACHE_DIR", "/env/folder");
  EXPECT_EQ(shaderCacheFolder(""), fs::path("/env/folder"));
  EXPECT_EQ(shaderCacheFolder("/asked"), fs::path("/asked"));   // the request comes first
  ScopedEnv off("SFFD_SHADER_CACHE_DISABLE", "1");
  EXPECT_EQ(shaderCacheFolder(""), std::nullopt);
  EXPECT_EQ(shaderCacheFolder("/asked"), fs::path("/asked"));
  ScopedEnv zero("SFFD_SHADER_CACHE_DISABLE", "0");
  EXPECT_EQ(shaderCacheFolder(""), fs::path("/env/folder"));
}

}  // namespace
}  // namespace sffd
