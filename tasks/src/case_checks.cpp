// The checks of a case without the work (case_checks.hpp).
#include "pdamp/tasks/case_checks.hpp"

#include "pdamp/base/input_error.hpp"
#include "pdamp/tasks/damper_design.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/tasks/field.hpp"
#include "structure_support.hpp"

namespace pdamp::tasks {

void check_case(const case_file::Case& c, base::RunHooks& hooks) {
  if (c.task.kind == case_file::TaskKind::kDamperDesign) (void)run_damper_design(c);
  const auto grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);
  for (std::size_t i = 0; i < c.dampers.size(); ++i) {
    if (c.excitation.amplitude_m)
      (void)check_dem_run(c, i, case_file::dem_options(c, i, *c.excitation.amplitude_m, c.excitation.frequency_hz));
    // check_dem_field places the bed as every DEM run of the case would.
    (void)check_dem_field(c, i, grid, nullptr, c.field.threads, hooks.long_runs_accepted());
  }
  if (!c.structure) return;
  const detail::Setup setup = detail::make_setup(c, case_file::LossMethod::kFormulas);
  if (c.task.kind != case_file::TaskKind::kDecay || !c.task.decay) return;
  const Eigen::VectorXd q0 = case_file::initial_modal_amplitudes(c, setup.s, *c.task.decay);
  if (!(q0.cwiseAbs().maxCoeff() > 0.0))
    throw base::InputError(c.path, "/task/initial_state", "gives no modal amplitude (the load does not excite any kept mode)");
  const auto options = dem_decay_options(c, setup.s.modal, q0, c.task.decay->duration_s);
  hooks.note("pdamp validate: the DEM-in-the-loop decay (pdamp decay --method dem): " +
             estimate_text(estimate_coupled_decay(c, setup.s.modal, detail::dem_dampers(c), options)));
}

void require_task(const case_file::Case& c, case_file::TaskKind kind) {
  using case_file::TaskKind;
  const auto& t = c.task;
  const bool present = (kind == TaskKind::kFrf && t.frf) || (kind == TaskKind::kDecay && t.decay) ||
                       (kind == TaskKind::kModes && t.modes) || (kind == TaskKind::kFillingRatios && t.filling_ratios) ||
                       (kind == TaskKind::kPlacement && t.placement) || (kind == TaskKind::kClearance && t.clearance) ||
                       kind == TaskKind::kDamperDesign;
  if (t.kind == kind && present) return;
  const std::string name(case_file::to_string(kind));
  const std::string needed = kind == TaskKind::kFrf     ? "\"min_frequency_hz\", \"max_frequency_hz\", \"excitation\""
                             : kind == TaskKind::kDecay ? "\"initial_state\", \"duration_s\""
                                                        : "...";
  throw base::InputError(c.path, "/task",
                                "pdamp " + name + " needs a task of kind " + name + " (this case's task is '" +
                                    std::string(case_file::to_string(t.kind)) + "'): give \"task\": {\"kind\": \"" + name +
                                    "\", " + needed + "} (docs/cases.md, Format 2)");
}

}  // namespace pdamp::tasks
