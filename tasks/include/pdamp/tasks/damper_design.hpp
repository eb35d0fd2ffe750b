// Task kind damper_design (a Level II case): the optimum stroke of the case's damper, the
// clearance for a target stroke, eta* at the operating point, the buffered-wall sizing and
// the eta*(X) curve, all from the closed forms.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/tasks/closed_forms.hpp"

namespace pdamp::tasks {

struct DamperDesignResult {
  std::string case_name;
  formulas::DamperModel family = formulas::DamperModel::kRolling;  ///< the model family designed for
  double clearance_m = 0.0;
  double bed_mass_kg = 0.0;
  double frequency_hz = 0.0;
  formulas::OptimumStroke optimum;
  double eta_star_at_design = 0.0;      ///< at optimum.x_opt_m
  double intensity_at_design = 0.0;
  struct Sizing {
    double target_stroke_m = 0.0;
    double clearance_m = 0.0;                           ///< whose design stroke is the target
    double container_inner_length_along_drive_m = 0.0;  ///< bed extent + that clearance
  };
  std::optional<Sizing> sizing;                 ///< when the case gives design.target_stroke_m
  std::optional<LossPoint> operating_point;     ///< when the case gives excitation.amplitude_m
  double operating_amplitude_m = 0.0;
  std::optional<formulas::BufferDesign> buffer;  ///< when the case has a buffer section
  std::string buffer_layer_material;
  std::vector<CurvePoint> curve;                ///< eta*(X) over the case's design sweep
  std::vector<std::string> warnings;
};

/// The damper_design study of a case with one damper of one layer. A closed form that
/// refuses the case's numbers, or a result that is not finite, is bad input of that case
/// (base::InputError naming the file), so `pdamp validate` catches what `pdamp run` would.
/// It runs on the primary process alone (on another: base::JobsServedElsewhere).
DamperDesignResult run_damper_design(const case_file::Case& c, base::Executor& executor = base::local_executor());
/// The result keys (task, case, model, clearance_m, optimum, sizing, operating_point, buffer);
/// "warnings" and "outputs" are the caller's.
nlohmann::json to_json(const DamperDesignResult& result);

}  // namespace pdamp::tasks
