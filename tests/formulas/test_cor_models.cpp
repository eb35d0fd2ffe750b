// Tests of cor_models (in progress).
#include <catch2/catch.hpp>
