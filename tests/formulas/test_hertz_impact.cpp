// Tests of hertz_impact (in progress).
#include <catch2/catch.hpp>
