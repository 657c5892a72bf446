#pragma once
// A directory of the running test's own for the files it writes, so that tests run side by side
// (ctest -j) never share one.

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace aloft::test {

// Makes, empty, and returns <system temp>/aloft-<label>-<test name>-<process id>. Call it from a test
// or its fixture, once per label (a second call empties the same directory); the caller removes it
// (fs::remove_all) when done.
inline std::filesystem::path make_test_dir(const std::string& label) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("aloft-" + label + "-" + std::string(info ? info->name() : "none") + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace aloft::test
