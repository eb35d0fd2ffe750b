// The error of a case file: file, JSON pointer and rule (the CLI exits 2 with it).
#pragma once

#include "pdamp/base/input_error.hpp"

namespace pdamp::case_file {

/// A case (or a file it names, e.g. modal data) breaks a rule. what() is
/// "<file>: <pointer>: <rule>"; file(), pointer() and rule() give the parts.
class CaseError : public base::InputError {
 public:
  using base::InputError::InputError;
};

}  // namespace pdamp::case_file
