// Tests of bed_packing (in progress).
#include <catch2/catch.hpp>
