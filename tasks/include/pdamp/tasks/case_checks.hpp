// Every check that the studies of a case make before they start, without the work
// (pdamp validate): the damper design's closed forms, each damper's DEM run and DEM field,
// the structure's modal model and a decay's initial state.
#pragma once

#include "pdamp/case_file/case.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

/// base::InputError naming the file and key of the first check that fails. A
/// format-2 case's structure is built as a run builds it (its modal model solved after the
/// size checks), a decay's initial state must move a kept mode, and the cost of the case's
/// DEM-in-the-loop decay (pdamp decay --method dem) is given to `hooks` as a note.
void check_case(const case_file::Case& c, base::RunHooks& hooks = base::silent_hooks());

/// InputError naming /task unless the case's task is of `kind` (with its settings), saying
/// which keys such a task needs.
void require_task(const case_file::Case& c, case_file::TaskKind kind);

}  // namespace pdamp::tasks
