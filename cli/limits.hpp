// The ranges of the CLI's flags: the case format's (pdamp/case_file/ranges.hpp), one
// source of truth for a quantity whether a flag or a case key gives it.
#pragma once

#include "pdamp/case_file/ranges.hpp"

namespace pdamp::cli {

using case_file::Range;
namespace limits = case_file::limits;

}  // namespace pdamp::cli
