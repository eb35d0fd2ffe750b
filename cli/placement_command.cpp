// pdamp optimize (and pdamp run) on task kind placement: case_file::placement_problem ->
// optimizer::optimize_placement_on_beam or _at_points -> the chosen site, the damping per
// target mode there and at the case's own site, placement.csv and its plot.
#include "placement_command.hpp"

#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "errors.hpp"
#include "output.hpp"
#include "output.hpp"
#include "structure_commands.hpp"
#include "pdamp/case_file/placement_problem.hpp"
#include "pdamp/optimizer/placement.hpp"
#include "pdamp/strict_json/input_file.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace opt = optimizer;
using case_file::Case;

json number_or_null(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json site_json(const opt::PlacementPoint& p) {
  json modes = json::array();
  for (const auto& m : p.modes)
    modes.push_back({{"mode", m.mode + 1},
                     {"natural_frequency_hz", m.natural_frequency_hz},
                     {"drive_shape", m.drive_shape},
                     {"modal_amplitude", m.modal_amplitude},
                     {"damper_amplitude_m", m.damper_amplitude_m},
                     {"eta_star", m.eta_star},
                     {"modal_mass_ratio", m.modal_mass_ratio},
                     {"added_damping_ratio", m.added_damping_ratio},
                     {"rotation_ratio", number_or_null(m.rotation_ratio)},
                     {"rotation_flagged", m.rotation_flagged},
                     {"loss_warnings", surrogate::describe_loss_warnings(m.loss_warnings)}});
  return {{"site", p.site}, {"position_m", number_or_null(p.position_m)}, {"objective", p.objective}, {"modes", modes}};
}

/// "x = 1.25 m" on a beam, the point's name among candidate points.
std::string site_text(const opt::PlacementPoint& p) {
  return std::isfinite(p.position_m) ? "x = " + format_number(p.position_m, 6) + " m" : "'" + p.site + "'";
}

std::string modes_text(const opt::PlacementPoint& p) {
  std::string out;
  for (const auto& m : p.modes) {
    if (!out.empty()) out += "; ";
    out += "mode " + std::to_string(m.mode + 1) + ": X = " + format_number(m.damper_amplitude_m * 1e3, 4) +
           " mm, eta* = " + format_number(m.eta_star, 3) + ", zeta_add = " + format_number(100.0 * m.added_damping_ratio, 4) +
           " %";
    if (m.rotation_flagged)
      out += ", rotation " + (std::isfinite(m.rotation_ratio) ? format_number(100.0 * m.rotation_ratio, 3) + " %" : "> 100 %");
  }
  return out;
}

/// placement.csv (one row per evaluated site; columns per target mode) and its plot: the
/// added damping of each target mode and the objective against the position (beam) or the
/// candidate point, with the chosen and the case's own site marked.
std::vector<std::string> write_files(OutputDir& files, const Case& c, const opt::PlacementResult& r, bool beam) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "site,position_m,objective";
  for (const auto& m : r.best.modes) {
    const std::string k = "mode" + std::to_string(m.mode + 1);
    csv << ',' << k << "_frequency_hz," << k << "_damper_amplitude_m," << k << "_eta_star," << k
        << "_added_damping_ratio," << k << "_rotation_ratio";
  }
  csv << '\n';
  for (const auto& p : r.scan) {
    csv << p.site << ',' << (beam ? p.position_m : NAN) << ',' << p.objective;
    for (const auto& m : p.modes)
      csv << ',' << m.natural_frequency_hz << ',' << m.damper_amplitude_m << ',' << m.eta_star << ','
          << m.added_damping_ratio << ',' << (std::isfinite(m.rotation_ratio) ? m.rotation_ratio : -1.0);
    csv << '\n';
  }
  files.add("placement.csv", csv.str());

  std::ostringstream gp;
  gp << "# added damping against the damper's site (pdamp optimize, task placement); run: gnuplot placement.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(c.name + ": damper placement") << " noenhanced\n"
     << "set ylabel 'added damping ratio {/Symbol z}_{add} / %'\nset grid\nset key outside right top\n";
  const std::string x = beam ? "2" : "0";  // the position, or the row number with the point's name as tic
  if (beam) {
    gp << "set xlabel 'damper position along the beam x / m'\n"
       << "set xrange [" << r.scan.front().position_m << ":" << r.scan.back().position_m << "]\n"
       << "set arrow from " << r.best.position_m << ", graph 0 to " << r.best.position_m
       << ", graph 1 nohead lc rgb 'black' dt 2\n"
       << "set label 'chosen' at " << r.best.position_m << ", graph 0.97 left offset 0.5,0\n";
    if (r.current)
      gp << "set arrow from " << r.current->position_m << ", graph 0 to " << r.current->position_m
         << ", graph 1 nohead lc rgb 'gray50' dt 3\n"
         << "set label 'case site' at " << r.current->position_m << ", graph 0.91 left offset 0.5,0 tc rgb 'gray40'\n";
  } else {
    gp << "set xlabel 'candidate point'\nset offsets 0.5, 0.5, 0, 0\n";
  }
  const std::string style = beam ? "with lines" : "with linespoints pt 7";
  gp << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'placement.svg' : 'placement.png'\n"
     << "  plot 'placement.csv' using " << x << ":($3*100)" << (beam ? "" : ":xticlabels(1)") << " every ::1 " << style
     << " lw 3 lc rgb 'black' title "
     << gnuplot_string(c.task.placement->objective == opt::PlacementObjective::kWorstMode ? "objective (worst mode)"
                                                                                        : "objective (weighted mean)");
  for (std::size_t k = 0; k < r.best.modes.size(); ++k) {
    const int column = 4 + 5 * static_cast<int>(k) + 3;  // modeN_added_damping_ratio
    gp << ", \\\n       '' using " << x << ":($" << column << "*100) every ::1 " << style << " lw 2 title "
       << gnuplot_string("mode " + std::to_string(r.best.modes[k].mode + 1));
  }
  gp << "\n}\n";
  return files.add_plot("placement.gp", gp.str(), {"placement.png", "placement.svg"});
}

}  // namespace

int run_placement_task(const ParsedArgs& args, const Case& c) {
  if (args.has("--verify"))
    throw InputError("--verify", "", "task kind placement has no DEM verification yet (filling_ratios has)");
  if (args.optional_text("--method").value_or("") == "dem")
    throw InputError("--method", "", "'dem': task kind placement takes formulas or field");
  const case_file::LossMethod method = loss_method(args);
  const case_file::PlacementTask& task = *c.task.placement;
  std::unique_ptr<OutputDir> files;
  if (const auto dir = args.optional_text("-o")) files = std::make_unique<OutputDir>(*dir);
  case_file::PlacementProblem p = case_file::placement_problem(c, method);

  opt::Options solver = opt::placement_solver_options();
  if (const auto name = args.optional_text("--backend")) {
    const auto backend = opt::backend_from_string(*name);
    if (!backend) throw InputError("--backend", "", "'" + *name + "': must be nlopt or ipopt");
    solver.backend = *backend;
  } else {
    solver.backend = *opt::backend_from_string(task.backend);
  }
  opt::PlacementResult r;
  try {
    r = p.beam ? opt::optimize_placement_on_beam(*p.beam, p.options, solver, p.current_position_m)
               : opt::optimize_placement_at_points(p.modal, p.candidate_points, p.options);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, "/task", e.what());
  }
  std::vector<std::string> warnings = p.warnings;
  warnings.insert(warnings.end(), r.warnings.begin(), r.warnings.end());
  if (!std::isfinite(r.best.objective)) throw NumericalError("pdamp optimize: the placement objective is not finite");

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
  json result = {{"task", "placement"},
                 {"case", c.name},
                 {"method", std::string(case_file::to_string(method))},
                 {"damper", p.options.damper.name},
                 {"objective", {{"kind", std::string(opt::to_string(p.options.objective))},
                                {"unit", "damping ratio"},
                                {"value", r.best.objective}}},
                 {"design", site_json(r.best)},
                 {"current", r.current ? site_json(*r.current) : json(nullptr)},
                 {"improvement_over_current",
                  r.current && r.current->objective > 0.0 ? json(r.best.objective / r.current->objective) : json(nullptr)},
                 {"sites_evaluated", r.scan.size()},
                 {"solver", solver_json},
                 {"verification", nullptr},
                 {"solve_time_s", r.solve_time_s}};
  json outputs = json::array();
  if (files) {
    for (auto& w : write_files(*files, c, r, p.beam.has_value())) warnings.push_back(w);
    result["file"] = (files->dir() / "placement.json").string();
    result["warnings"] = warnings;
    files->add_json("case_resolved.json", c.resolved);
    files->add_json("placement.json", result);
    stage_run_report(*files, c, result, warnings);
    outputs = files->commit();
  } else {
    result["file"] = nullptr;
  }
  result["warnings"] = warnings;
  result["outputs"] = outputs;
  for (const auto& w : warnings) std::cerr << "pdamp: warning: " << strict_json::printable(w) << "\n";
  if (args.has("--json")) {
    std::cout << result.dump(2) << "\n";
    return kExitOk;
  }
  std::vector<std::pair<std::string, std::string>> rows = {
      {"case", c.name},
      {"objective", std::string(opt::to_string(p.options.objective)) + " of zeta_add over the target modes"},
      {"chosen site", site_text(r.best) + ", objective " + format_number(100.0 * r.best.objective, 5) + " %"},
      {"chosen, per mode", modes_text(r.best)}};
  if (r.current) {
    rows.push_back({"case site", site_text(*r.current) + ", objective " + format_number(100.0 * r.current->objective, 5) + " %"});
    rows.push_back({"case site, per mode", modes_text(*r.current)});
  }
  rows.push_back({"solver", r.refined ? s.brief_report() : std::string("every candidate point evaluated")});
  rows.push_back({"time", format_number(r.solve_time_s, 4) + " s, " + std::to_string(r.evaluations) + " sites"});
  for (const auto& path : outputs) rows.push_back({"wrote", path.get<std::string>()});
  std::cout << key_value_table(rows);
  return kExitOk;
}

}  // namespace pdamp::cli
