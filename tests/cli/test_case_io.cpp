// Command-line tests (in progress).
#include <catch2/catch.hpp>
