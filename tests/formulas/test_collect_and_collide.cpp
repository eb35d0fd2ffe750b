// Tests of collect_and_collide (in progress).
#include <catch2/catch.hpp>
