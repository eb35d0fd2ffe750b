// Helper of the case_file tests: a case that must be refused with a given CaseError.
#pragma once

#include <catch2/catch.hpp>
#include <string>

#include "pdamp/case_file/case.hpp"

namespace pdamp::test {

/// Loading `path` throws a CaseError naming `file`, `pointer` and a rule containing
/// `rule`; what() reads "<file>[: <pointer>]: <rule>".
inline void require_case_error(const std::string& path, const std::string& file, const std::string& pointer,
                               const std::string& rule) {
  try {
    (void)case_file::load_case(path);
    FAIL("no CaseError for " << pointer);
  } catch (const case_file::CaseError& e) {
    CHECK(e.file() == file);
    CHECK(e.pointer() == pointer);
    CHECK_THAT(e.rule(), Catch::Contains(rule));
    CHECK(std::string(e.what()) == file + (pointer.empty() ? "" : ": " + pointer) + ": " + e.rule());
  }
}

}  // namespace pdamp::test
