// Options of the optimiser: names of the enums and validation.
#include "pdamp/optimizer/options.hpp"

#include <cmath>

#include "pdamp/base/number_text.hpp"
#include "validation.hpp"

namespace pdamp::optimizer {

std::string_view to_string(Backend backend) {
  switch (backend) {
    case Backend::kNlopt: return "nlopt";
    case Backend::kIpopt: return "ipopt";
  }
  return "unknown";
}

std::optional<Backend> backend_from_string(std::string_view name) {
  for (Backend backend : {Backend::kNlopt, Backend::kIpopt}) {
    if (name == to_string(backend)) return backend;
  }
  return std::nullopt;
}

std::string_view to_string(NloptLocalAlgorithm algorithm) {
  switch (algorithm) {
    case NloptLocalAlgorithm::kSlsqp: return "LD_SLSQP";
    case NloptLocalAlgorithm::kCobyla: return "LN_COBYLA";
  }
  return "unknown";
}

std::vector<std::string> Options::validate() const {
  std::vector<std::string> problems;
  const auto rule = [&](const char* field, double value, bool holds, const char* text) {
    if (!holds) problems.push_back(std::string(field) + " = " + base::format_number(value, 10) + ": must be " + text);
  };
  rule("max_evaluations", max_evaluations, max_evaluations >= 2, ">= 2");
  if (global_stage) {
    rule("global_evaluations", global_evaluations, global_evaluations >= 1 && global_evaluations < max_evaluations,
         "in [1, max_evaluations) (leave evaluations to the local stage)");
  }
  rule("relative_tolerance", relative_tolerance, relative_tolerance > 0.0 && relative_tolerance <= 0.1,
       "in (0, 0.1]");
  rule("constraint_tolerance", constraint_tolerance, constraint_tolerance > 0.0 && constraint_tolerance <= 1.0,
       "in (0, 1]");
  return problems;
}

}  // namespace pdamp::optimizer
