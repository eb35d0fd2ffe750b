// Optimiser options shared by the NLopt and Ipopt back ends (the optimisation
// issue adds Problem and Summary; the back ends stay private in src/).
#pragma once

namespace pdamp::optimizer {

enum class Backend { kNlopt, kIpopt };

struct Options {
  Backend backend = Backend::kNlopt;
  double relative_tolerance = 1e-8;  ///< on the design variables, dimensionless
  int max_evaluations = 10000;
};

}  // namespace pdamp::optimizer
