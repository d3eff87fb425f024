// A test fixture that gives each test a fresh directory of its own for the files it
// writes, removed after the test.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace mcrewave {

class FileFixture : public ::testing::Test {
 protected:
  // prefix names the directory: <temp>/mcrewave_<prefix>_<test>_<pid>.
  explicit FileFixture(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ = std::filesystem::path(::testing::TempDir()) /
                 ("mcrewave_" + prefix_ + "_" + std::string(info->name()) + "_" +
                  std::to_string(::getpid()));
    std::filesystem::remove_all(directory_);
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string PathOf(const std::string& name) const { return (directory_ / name).string(); }

  // Writes `content` byte for byte to `name`; returns its path.
  std::string WriteFile(const std::string& name, const std::string& content) const {
    const std::string path = PathOf(name);
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

 private:
  std::string prefix_;
  std::filesystem::path directory_;
};

}  // namespace mcrewave
