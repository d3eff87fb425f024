// The test binary's main. ctest runs one process per test, two or more at a time,
// and many tests write files under ::testing::TempDir() with fixed names (the
// fixtures of one suite each write the same folder in their own process). Each
// process therefore gets a folder of its own, made here and named in TEST_TMPDIR
// (which ::testing::TempDir() reads), so no test ever reads or deletes another
// process's files; the folder is removed when the tests are done.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const std::string pattern = ::testing::TempDir() + "mcrewave_tests_XXXXXX";
  std::vector<char> folder(pattern.begin(), pattern.end());
  folder.push_back('\0');
  if (mkdtemp(folder.data()) == nullptr) {
    std::perror(("cannot create a temporary folder from " + pattern).c_str());
    return EXIT_FAILURE;
  }
  setenv("TEST_TMPDIR", folder.data(), 1);
  const int status = RUN_ALL_TESTS();
  std::error_code ignored;
  std::filesystem::remove_all(folder.data(), ignored);
  return status;
}
