// Tests of complex_power (in progress).
#include <catch2/catch.hpp>
