// The error of a case file: file, JSON pointer and rule (the CLI exits 2 with it).
#pragma once

#include "pdamp/strict_json/input_error.hpp"

namespace pdamp::case_file {

/// A case (or a file it names, e.g. modal data) breaks a rule. what() is
/// "<file>: <pointer>: <rule>"; file(), pointer() and rule() give the parts.
class CaseError : public strict_json::InputError {
 public:
  using strict_json::InputError::InputError;
};

}  // namespace pdamp::case_file
