// Sweep evaluator of the closed-form collect-and-collide models (formulas/).
#include <string>
#include <vector>

#include "pdamp/base/checks.hpp"

#include "pdamp/surrogate/sweep.hpp"  // declares formula_evaluator next to run_sweep
#include "text_util.hpp"

namespace pdamp::surrogate {

PointEvaluator formula_evaluator(formulas::DamperModel model, double clearance_m, double bed_mass_kg,
                                 const formulas::ModelOptions& options) {
  std::vector<std::string> problems = options.validate();
  if (!base::positive_finite(clearance_m))
    problems.push_back(base::violation("clearance_m", clearance_m, "> 0 and finite"));
  if (!base::positive_finite(bed_mass_kg))
    problems.push_back(base::violation("bed_mass_kg", bed_mass_kg, "> 0 and finite"));
  detail::throw_if_any(problems, "formula evaluator");
  return [model, clearance_m, bed_mass_kg, options](double frequency_hz, double amplitude_m) {
    const auto loss = formulas::reduced_loss_factor(model, clearance_m, amplitude_m, frequency_hz, options);
    FieldPoint p;
    p.eta_star = loss.eta_star;
    p.eta_star_stderr = 0.0;  // a closed form has no sampling error
    p.e_diss_j = formulas::dissipated_energy_measure(loss.eta_star, bed_mass_kg, loss.velocity_amplitude_m_s);
    p.motion_mode = std::string(formulas::to_string(loss.regime));
    p.status = PointStatus::kOk;
    return p;
  };
}

}  // namespace pdamp::surrogate
