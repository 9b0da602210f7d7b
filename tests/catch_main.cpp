// Catch2's runner, compiled once for every test executable (it takes longer to compile than
// most test files).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace {

/// The test process's own temporary folder, made its TMPDIR so that every file its cases write
/// there (and the processes they start, which inherit it) goes into it. Removed when every case
/// passed; kept, and named, when one failed, for a look at what it left. Without it each run of
/// the suite left about a thousand folders in /tmp: most cases cannot remove theirs when a
/// check fails half-way, and many never tried.
class TestProcessTemporaryFolder {
public:
    TestProcessTemporaryFolder()
        : folder_(std::filesystem::temp_directory_path() /
                  ("grainlink-tests-" + std::to_string(::getpid()))) {
        std::filesystem::remove_all(folder_);
        std::filesystem::create_directories(folder_);
        ::setenv("TMPDIR", folder_.c_str(), 1);
    }

    /// Removes the folder, or names it where a case failed.
    void finish(int failed) const {
        if (failed) {
            std::cerr << "the test files are kept in " << folder_.string() << '\n';
            return;
        }
        std::error_code ignored; // a child that outlives its test may still be writing
        std::filesystem::remove_all(folder_, ignored);
    }

private:
    std::filesystem::path folder_;
};

} // namespace

int main(int argc, char *argv[]) {
    // ctest learns the cases from their names, and CMake splits a name at ';' into two that match
    // no case: such a case would pass in ctest without ever running. Refused here, so that the
    // build's test discovery fails, naming it.
    int bad = 0;
    for (const Catch::TestCase &test : Catch::getRegistryHub().getTestCaseRegistry().getAllTests())
        if (test.name.find(';') != std::string::npos) {
            std::cerr << test.lineInfo << ": test case name contains ';' (ctest would split it and "
                      << "never run it): " << test.name << '\n';
            ++bad;
        }
    if (bad)
        return 1;
    Catch::Session session;
    if (const int wrong = session.applyCommandLine(argc, argv))
        return wrong;
    const TestProcessTemporaryFolder temporary;
    const int result = session.run();
    // A listing (ctest's discovery) returns how many it listed, not failures.
    const Catch::ConfigData &asked = session.configData();
    const bool listed =
        asked.listTests || asked.listTestNamesOnly || asked.listTags || asked.listReporters;
    temporary.finish(listed ? 0 : result);
    return result;
}
