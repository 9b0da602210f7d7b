// Catch2's runner, compiled once for every test executable (it takes longer to compile than
// most test files).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <iostream>

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
    return Catch::Session().run(argc, argv);
}
