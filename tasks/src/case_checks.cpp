// The checks of a case without the work (case_checks.hpp).
#include "pdamp/tasks/case_checks.hpp"

#include "pdamp/tasks/damper_design.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/tasks/field.hpp"

namespace pdamp::tasks {

void check_case(const case_file::Case& c) {
  if (c.task.kind == case_file::TaskKind::kDamperDesign) (void)run_damper_design(c);
  const auto grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);
  for (std::size_t i = 0; i < c.dampers.size(); ++i) {
    if (c.excitation.amplitude_m)
      (void)check_dem_run(c, i, case_file::dem_options(c, i, *c.excitation.amplitude_m, c.excitation.frequency_hz));
    // check_dem_field places the bed as every DEM run of the case would.
    (void)check_dem_field(c, i, grid, nullptr, c.field.threads);
  }
}

}  // namespace pdamp::tasks
