// formulas' names for the strict input reader (pdamp/base/input_file.hpp), which
// the COR-table reader (cor_models.cpp) and structure/ use: reading a user's file
// safely, JSON without duplicate keys, one-line printable messages. New code includes
// pdamp/base/input_file.hpp directly.
#pragma once

#include "pdamp/base/input_file.hpp"

namespace pdamp::formulas {

using base::parse_json_document;
using base::printable;
using base::read_input_file;

}  // namespace pdamp::formulas
