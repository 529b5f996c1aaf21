// A fixture for the readers' and writers' tests: a fresh folder per test, removed afterwards, files
// written into it; and the check that a refused input gives its one-line message.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>

#include <sffd/error.h>

namespace sffd::test {

class TempFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("sffd_") + t->test_suite_name() + "_" + t->name() + "_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Writes `bytes` to the file `name` of the folder; returns its path.
  std::string write(const std::string& name, const std::string& bytes) const {
    std::string p = path(name);
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  std::filesystem::path dir_;
};

// Runs f, expects an input Error whose message starts with "file:line: " (or "file: " for line 0) and
// contains `part`.
inline void expectInputError(const std::function<void()>& f, const std::string& file, size_t line, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no error for " << file << " (expected '" << part << "')";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
    std::string prefix = file + (line ? ":" + std::to_string(line) : std::string()) + ": ";
    EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << "message '" << e.what() << "' should start with '" << prefix << "'";
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "message '" << e.what() << "' should mention '" << part << "'";
  } catch (const std::exception& e) {
    ADD_FAILURE() << "unexpected exception type: " << e.what();
  }
}

}  // namespace sffd::test
