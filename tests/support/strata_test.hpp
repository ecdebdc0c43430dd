#pragma once
// Test helpers: where the shared real data and the test outputs live.
#include <filesystem>
#include <string>

namespace strata::test {

/// ../shared/data/<relative> (compiled in as STRATA_DATA_DIR).
std::string dataPath(const std::string& relative);
/// build/test-output/<suite>/ , created on demand: images and reports a test leaves behind.
std::filesystem::path outputDir(const std::string& suite);
/// A fresh empty temporary folder for this test (removed at exit unless STRATA_KEEP_TMP=1).
std::filesystem::path tempDir(const std::string& name);

}  // namespace strata::test
