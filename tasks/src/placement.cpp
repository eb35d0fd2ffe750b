// Task kind placement (placement.hpp).
#include "pdamp/tasks/placement.hpp"

#include "pdamp/case_file/placement_problem.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/surrogate/loss_model.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace opt = optimizer;
using nlohmann::json;

PlacementStudy run_placement(const case_file::Case& c, const PlacementOptions& options, base::Executor& executor) {
  executor.primary_only();  // the formulas or fields of a few sites: nothing to spread
  const case_file::PlacementTask& task = *c.task.placement;
  case_file::PlacementProblem p = case_file::placement_problem(c, options.method);
  opt::Options solver = opt::placement_solver_options();
  solver.backend = options.backend.value_or(*opt::backend_from_string(task.backend));
  PlacementStudy out;
  out.case_name = c.name;
  out.method = options.method;
  out.damper = p.options.damper.name;
  out.objective = p.options.objective;
  out.beam = p.beam.has_value();
  try {
    out.result = p.beam ? opt::optimize_placement_on_beam(*p.beam, p.options, solver, p.current_position_m)
                        : opt::optimize_placement_at_points(p.modal, p.candidate_points, p.options);
  } catch (const std::invalid_argument& e) {
    throw base::InputError(c.path, "/task", e.what());
  }
  out.warnings = p.warnings;
  out.warnings.insert(out.warnings.end(), out.result.warnings.begin(), out.result.warnings.end());
  if (!std::isfinite(out.result.best.objective))
    throw base::NumericalError("pdamp optimize: the placement objective is not finite");
  return out;
}

json to_json(const PlacementStudy& study) {
  const auto& r = study.result;
  const auto& s = r.summary;
  const json solver_json =
      r.refined ? json{{"backend", std::string(opt::to_string(s.backend))},
                       {"stages", "scan of " + std::to_string(r.scan.size()) + " positions, then a local refinement"},
                       {"outcome", std::string(opt::to_string(s.outcome))},
                       {"iterations", s.iterations},
                       {"evaluations", r.evaluations},
                       {"refinement_evaluations", s.evaluations},
                       {"message", s.message},
                       {"report", s.brief_report()}}
                : json{{"backend", "scan"},
                       {"stages", "every candidate point evaluated"},
                       {"outcome", "converged"},
                       {"iterations", 0},
                       {"evaluations", r.evaluations}};
  return {{"task", "placement"},
          {"case", study.case_name},
          {"method", std::string(case_file::to_string(study.method))},
          {"damper", study.damper},
          {"objective", {{"kind", std::string(opt::to_string(study.objective))}, {"unit", "damping ratio"},
                         {"value", r.best.objective}}},
          {"design", base::to_json(r.best)},
          {"current", r.current ? base::to_json(*r.current) : json(nullptr)},
          {"improvement_over_current",
           r.current && r.current->objective > 0.0 ? json(r.best.objective / r.current->objective) : json(nullptr)},
          {"sites_evaluated", r.scan.size()},
          {"solver", solver_json},
          {"verification", nullptr},
          {"solve_time_s", r.solve_time_s}};
}

}  // namespace pdamp::tasks
