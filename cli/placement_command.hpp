// pdamp optimize and pdamp run on task kind placement (issue 12 §1.4): where a damper adds
// the most damping to the case's target modes (docs/optimizer.md, "Placement").
#pragma once

#include "args.hpp"
#include "pdamp/case_file/case.hpp"

namespace pdamp::cli {

/// Runs the case's placement task: --method formulas|field (the layers' loss models),
/// --backend nlopt|ipopt (the beam's local refinement), -o DIR, --json.
int run_placement_task(const ParsedArgs& args, const case_file::Case& c);

}  // namespace pdamp::cli
