#pragma once
// Where the tests find the real data sets of ../shared/data (refahi2021 centroids, MorphoGraphX
// and openalea meshes): $TP_SHARED_DATA_DIR (ctest sets it from the CMake cache variable of that
// name), else next to the source tree, as in CI. A checkout elsewhere has no such folder: the
// tests that read it are then skipped with the path they looked for (CMake warns at configure
// time), and run everywhere the data is.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace tp::test {

inline std::filesystem::path sharedDataDir() {
  if (const char* env = std::getenv("TP_SHARED_DATA_DIR"); env && *env) return env;
  return std::filesystem::path(TP_SOURCE_DIR) / ".." / "shared" / "data";
}

/// A file of the shared data, as a string path.
inline std::string sharedDataFile(const std::string& relative) {
  return (sharedDataDir() / relative).string();
}

}  // namespace tp::test

/// Skips the current test when the data file `path` does not exist.
#define TP_SKIP_WITHOUT_DATA(path)                                                           \
  if (!std::filesystem::exists(path))                                                        \
  GTEST_SKIP() << "shared data not found: " << (path)                                        \
               << " (set TP_SHARED_DATA_DIR to the folder of the data sets)"
