// Catch2's runner, compiled once for every test executable (it takes longer to compile than
// most test files).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
