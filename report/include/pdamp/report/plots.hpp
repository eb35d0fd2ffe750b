// gnuplot pictures of pdamp's results: the data files and scripts that draw them.
#pragma once

#include <string>
#include <vector>

#include "pdamp/case_file/case.hpp"
#include "pdamp/report/output_dir.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/tasks/closed_forms.hpp"

namespace pdamp::report {

using tasks::CurvePoint;

/// eta_curve.csv and its plot (PNG, SVG) with onset, ideal peak and design stroke
/// marked. Returns warnings (e.g. gnuplot missing).
std::vector<std::string> write_eta_curve(OutputDir& out, const std::vector<CurvePoint>& curve,
                                         const formulas::OptimumStroke& landmarks, double frequency_hz,
                                         const std::string& title);

/// force_velocity.png/.svg from time_series.csv (staged in `out` already): the
/// container force on the bed and the container velocity over the analysed periods.
std::vector<std::string> write_force_velocity_plot(OutputDir& out, const std::string& title);

/// field_table.csv, field_map.dat, field_cuts_formula.csv, field_cuts_points.csv, the eta* cuts along axis 1 (at most 12)
/// with the closed form, and the heat map with motion modes (when both axes have >= 2
/// nodes); the closed form is that of `damper`, the titles name `case_name`.
std::vector<std::string> write_field_pictures(OutputDir& out, const surrogate::EffectiveField& field,
                                                  const std::string& case_name, const case_file::DamperSpec& damper);

}  // namespace pdamp::report
