// Every check that the studies of a case make before they start, without the work
// (pdamp validate): the damper design's closed forms, each damper's DEM run and DEM field.
#pragma once

#include "pdamp/case_file/case.hpp"

namespace pdamp::tasks {

/// strict_json::InputError naming the file and key of the first check that fails.
void check_case(const case_file::Case& c);

/// InputError naming /task unless the case's task is of `kind` (with its settings), saying
/// which keys such a task needs.
void require_task(const case_file::Case& c, case_file::TaskKind kind);

}  // namespace pdamp::tasks
