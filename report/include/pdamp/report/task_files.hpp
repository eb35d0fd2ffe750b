// The files of each task's result: CSV tables, gnuplot pictures and the data they draw,
// staged into a run's output folder. Each returns warnings (gnuplot missing or failing).
#pragma once

#include <string>
#include <vector>

#include "pdamp/case_file/case.hpp"
#include "pdamp/report/output_dir.hpp"
#include "pdamp/tasks/closed_forms.hpp"
#include "pdamp/tasks/damper_design.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/tasks/field.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/tasks/frf.hpp"
#include "pdamp/tasks/modes.hpp"
#include "pdamp/tasks/clearance.hpp"
#include "pdamp/tasks/placement.hpp"
#include "pdamp/tasks/sensitivity.hpp"

namespace pdamp::report {

/// eta_curve.csv and its plot.
std::vector<std::string> write_files(OutputDir& out, const tasks::DamperDesignResult& design);
/// pdamp loss: eta_curve.csv and its plot (title names the model asked for).
std::vector<std::string> write_files(OutputDir& out, const tasks::LossStudy& loss);
/// time_series.csv, particles_<k>.vtk (ParaView) and force_velocity.png/.svg.
std::vector<std::string> write_files(OutputDir& out, const tasks::DemRunResult& dem);
/// field.json, scattered_fit.json (when fitted), the table, heat map and cuts with the case
/// damper's closed form.
std::vector<std::string> write_files(OutputDir& out, const tasks::FieldResult& field, const case_file::Case& c);
/// A shard of a sweep: `summary` as shard.json and the case file it ran as shard_case.json
/// (the merge reads it back).
void write_shard_files(OutputDir& out, const nlohmann::json& summary, const case_file::Case& c);
/// sensitivity.csv, sensitivity_tornado.csv and the tornado plot.
std::vector<std::string> write_files(OutputDir& out, const tasks::SensitivityResult& study);
/// modes.csv, backbone_mode<j>.csv and the backbone plot.
std::vector<std::string> write_files(OutputDir& out, const tasks::ModesResult& modes);
/// frf.csv, frf_branches.csv and frf.png (harmonic balance); frf_dem.csv and frf_dem.png
/// (stepped sine); frf_dem_sweep.csv and its plot (linear sweep); frf_compare.csv and its
/// plot (--compare).
std::vector<std::string> write_files(OutputDir& out, const tasks::FrfResult& frf);
/// decay.csv and decay.png (averaging), decay_dem.csv and decay_dem.png (DEM).
std::vector<std::string> write_files(OutputDir& out, const tasks::DecayResult& decay);
/// designs.csv, decay_compare.csv and its plot; with the verification verify_decay.csv and its plot.
std::vector<std::string> write_files(OutputDir& out, const tasks::FillingRatiosResult& result);
/// placement.csv and its plot.
std::vector<std::string> write_files(OutputDir& out, const tasks::PlacementStudy& study);
/// clearance.csv (the peak against h) and its plot; with the verification
/// clearance_checks.csv and clearance_verify.csv (each clearance's predicted curve and DEM
/// points) and its plot.
std::vector<std::string> write_files(OutputDir& out, const tasks::ClearanceStudy& study);

}  // namespace pdamp::report
