// formulas' names for the strict input reader (pdamp/strict_json/input_file.hpp), which
// the COR-table reader (cor_models.cpp) and structure/ use: reading a user's file
// safely, JSON without duplicate keys, one-line printable messages. New code includes
// pdamp/strict_json/input_file.hpp directly.
#pragma once

#include "pdamp/strict_json/input_file.hpp"

namespace pdamp::formulas {

using strict_json::parse_json_document;
using strict_json::printable;
using strict_json::read_input_file;

}  // namespace pdamp::formulas
