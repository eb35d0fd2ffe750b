// The files of each task's result (task_files.hpp).
#include "pdamp/report/task_files.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <sstream>

#include "pdamp/base/record.hpp"
#include "pdamp/dem_reference/result_files.hpp"
#include "pdamp/report/plots.hpp"
#include "pdamp/report/structure_plots.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/scattered_fit.hpp"

namespace pdamp::report {

namespace fm = formulas;
namespace opt = optimizer;
namespace st = structure;
using Warnings = std::vector<std::string>;

namespace {

void append(Warnings& to, const Warnings& from) { to.insert(to.end(), from.begin(), from.end()); }

/// particles<suffix>.pvd and container<suffix>.pvd, ParaView series of one bed: its
/// particles at each snapshot and its containers moved by `container_positions_m` there.
void write_paraview_series(OutputDir& out, const std::string& suffix, const dem_reference::WorldOptions& world,
                           const std::vector<const dem_reference::ParticleSnapshot*>& particles,
                           const std::vector<dem_reference::Vec3>& container_positions_m) {
  if (particles.empty()) return;
  std::vector<std::pair<double, std::string>> particle_files, container_files;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double t = particles[i]->time_s;
    char number[32];
    std::snprintf(number, sizeof number, "_%04zu.vtp", i);
    const std::string particle_file = "particles" + suffix + number, container_file = "container" + suffix + number;
    dem_reference::write_vtp_snapshot(out.staged_path(particle_file).string(), *particles[i]);
    dem_reference::write_container_vtp(out.staged_path(container_file).string(), world, container_positions_m[i], t);
    particle_files.push_back({t, particle_file});
    container_files.push_back({t, container_file});
  }
  dem_reference::write_pvd_series(out.staged_path("particles" + suffix + ".pvd").string(), particle_files);
  dem_reference::write_pvd_series(out.staged_path("container" + suffix + ".pvd").string(), container_files);
}

}  // namespace

Warnings write_files(OutputDir& out, const tasks::DamperDesignResult& d) {
  return write_eta_curve(out, d.curve, d.optimum, d.frequency_hz, d.case_name);
}

Warnings write_files(OutputDir& out, const tasks::LossStudy& loss) {
  return write_eta_curve(out, loss.curve, loss.landmarks, loss.options.frequency_hz,
                         "pdamp loss --model " + std::string(fm::to_string(loss.options.model)));
}

Warnings write_files(OutputDir& out, const tasks::DemRunResult& r) {
  dem_reference::write_time_series_csv(out.staged_path("time_series.csv").string(), r.dem.series);
  // ParaView: the container's displacement along the drive at a snapshot's time is the
  // recorded container_position_m there (linear between samples).
  const auto& s = r.dem.series;
  std::vector<const dem_reference::ParticleSnapshot*> particles;
  std::vector<dem_reference::Vec3> containers;
  for (const auto& snapshot : r.dem.snapshots) {
    const double t = snapshot.time_s;
    double x = 0.0;
    if (s.time_s.size() == 1) {
      x = s.container_position_m.front();
    } else if (s.time_s.size() > 1) {
      const auto at = std::lower_bound(s.time_s.begin(), s.time_s.end(), t) - s.time_s.begin();
      const auto k = std::clamp<std::ptrdiff_t>(at, 1, static_cast<std::ptrdiff_t>(s.time_s.size()) - 1);
      const double w = std::clamp((t - s.time_s[k - 1]) / (s.time_s[k] - s.time_s[k - 1]), 0.0, 1.0);
      x = s.container_position_m[k - 1] + w * (s.container_position_m[k] - s.container_position_m[k - 1]);
    }
    particles.push_back(&snapshot);
    containers.push_back({x * r.drive_axis[0], x * r.drive_axis[1], x * r.drive_axis[2]});
  }
  write_paraview_series(out, "", r.world, particles, containers);
  return write_force_velocity_plot(out, r.case_name + ": X = " + format_number(r.amplitude_m * 1e3, 4) + " mm, f = " +
                                            format_number(r.frequency_hz, 4) + " Hz");
}

Warnings write_files(OutputDir& out, const tasks::FieldResult& r, const case_file::Case& c) {
  surrogate::write_effective_field(r.field, out.staged_path("field.json"));
  if (r.scattered_fit) surrogate::write_scattered_fit(*r.scattered_fit, out.staged_path("scattered_fit.json"));
  return write_field_pictures(out, r.field, c.name, c.dampers.front());
}

void write_shard_files(OutputDir& out, const nlohmann::json& summary, const case_file::Case& c) {
  out.add_json("shard.json", summary);
  std::ifstream in(c.path, std::ios::binary);
  out.add("shard_case.json", std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
}

Warnings write_files(OutputDir& out, const tasks::SensitivityResult& study) {
  const base::CsvTable<tasks::SensitivityRow> rows(
      {"parameter", "value", "unit", "eta_star", "eta_star_stderr", "delta_eta_star", "motion_mode",
       "apparent_mass_fraction", "closed_form_eta_star", "clearance_m", "bed_mass_kg", "status"});
  std::string csv = rows.header() + "\n";
  for (const auto& r : study.rows) csv += rows.row(r) + "\n";
  out.add("sensitivity.csv", csv);

  // The bars sorted by how far each parameter moves η* from the baseline, largest on top,
  // each end labelled with its value and η*, the DEM's standard errors as error bars.
  const tasks::Tornado t = tasks::tornado(study);
  const base::CsvTable<tasks::TornadoBar> bars(
      {"parameter", "eta_star_low", "eta_star_high", "value_at_low", "value_at_high",
       base::CsvColumn("eta_star_stderr_at_low").nan_as("0"), base::CsvColumn("eta_star_stderr_at_high").nan_as("0"),
       "effect"});
  std::string tornado = bars.header() + "\n";
  for (const auto& b : t.bars) tornado += bars.row(b) + "\n";
  out.add("sensitivity_tornado.csv", tornado);
  const double baseline = study.baseline_eta_star;
  std::string without;
  for (const auto& p : t.without_effect) without += (without.empty() ? "" : ", ") + p;
  // The x range holds every bar, its error bars, labels and the baseline.
  double x_min = baseline, x_max = baseline;
  for (const auto& b : t.bars) {
    x_min = std::min({x_min, b.low - (std::isfinite(b.stderr_at_low) ? b.stderr_at_low : 0.0)});
    x_max = std::max({x_max, b.high + (std::isfinite(b.stderr_at_high) ? b.stderr_at_high : 0.0)});
  }
  const double pad = 0.25 * std::max(x_max - x_min, 1e-3 * std::max(1.0, std::abs(baseline)));
  std::ostringstream gp;
  gp.precision(10);
  gp << "# tornado plot of pdamp sensitivity: eta* over each parameter's values, the largest effect on top;\n"
     << "# run: gnuplot sensitivity.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(study.case_name + ": sensitivity of eta* (one parameter at a time, " + study.source + ")");
  // A second title line (gnuplot's "\n" in a double-quoted piece) for what has no bar.
  if (!without.empty())
    gp << ".\"\\n\"."
       << gnuplot_string((study.source == "formulas" ? "no effect in the closed forms: " : "no effect on eta*: ") + without);
  gp << " noenhanced\n"
     << "set xlabel 'reduced loss factor {/Symbol h}*'\nset ytics noenhanced\nset grid x\nset key below\n"
     << "set xrange [" << x_min - pad << ":" << x_max + pad << "]\nset offsets 0, 0, 0.5, 0.5\n"
     << "set style fill solid 0.6 border -1\n"
     << "set arrow from " << baseline << ", graph 0 to " << baseline << ", graph 1 nohead lc rgb 'black' dt 2\n";
  gp << "do for [t in 'pngcairo svg'] {\n"
     // Wide enough for the second title line (about 7 px per character at 11 pt).
     << "  set terminal t size " << std::max<std::size_t>(1000, 140 + 7 * (30 + without.size())) << ","
     << 220 + 45 * static_cast<int>(t.bars.size()) << " enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'sensitivity.svg' : 'sensitivity.png'\n"
     << "  base = " << baseline << "\n"
     << "  plot 'sensitivity_tornado.csv' every ::1 using (base):($0):($2 < base ? $2 : base):($3 > base ? $3 : base):"
        "($0-0.3):($0+0.3):ytic(1) with boxxyerror lc rgb 'steelblue' title 'from the baseline to each value', \\\n"
     << "       '' every ::1 using 2:($0):6 with xerrorbars pt 7 ps 0.6 lc rgb 'black' title 'standard error', \\\n"
     << "       '' every ::1 using 3:($0):7 with xerrorbars pt 7 ps 0.6 lc rgb 'black' notitle, \\\n"
     << "       '' every ::1 using 2:($0):(sprintf('%.3g: %.3g ', $4, $2)) with labels right offset -1,0 font ',9' "
        "notitle, \\\n"
     << "       '' every ::1 using 3:($0):($5 == $4 ? '' : sprintf(' %.3g: %.3g', $5, $3)) with labels left offset 1,0 "
        "font ',9' notitle, \\\n"
     << "       NaN with lines dt 2 lc rgb 'black' title " << gnuplot_string("baseline " + format_number(baseline, 3)) << "\n"
     << "}\n";
  return out.add_plot("sensitivity.gp", gp.str(), {"sensitivity.png", "sensitivity.svg"});
}

namespace {

/// clearance_search.csv (one row per candidate: its objective, its added damping at each
/// stroke, the means of its DEM-checked decays), clearance_search_checks.csv (the decays) and
/// the objective against h with the DEM's means.
Warnings clearance_search_files(OutputDir& out, const std::string& case_name, const tasks::ModeClearanceSearchResult& s) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "clearance_m,inner_length_m,wall_layer_thickness_m,layer_tip_strain,buildable,objective,predicted_check_mean,"
         "dem_check_mean";
  for (const double x : s.amplitudes_m) csv << ",added_damping_ratio_at_" << x << "_m";
  csv << '\n';
  const auto number = [](double v) { return std::isfinite(v) ? base::format_number(v, 10) : std::string(); };
  for (const auto& c : s.candidates) {
    csv << c.clearance_m << ',' << c.inner_length_m << ',' << c.wall_layer_thickness_m << ',' << number(c.layer_tip_strain)
        << ',' << (c.buildable ? 1 : 0) << ',' << number(c.objective) << ',' << number(c.predicted_check_mean) << ','
        << number(c.dem_check_mean);
    for (const double zeta : c.added_damping_ratios) csv << ',' << number(zeta);
    csv << '\n';
  }
  out.add("clearance_search.csv", csv.str());
  if (s.verified) {
    const base::CsvTable<tasks::ModeDecayCheck> columns(
        {"damper_amplitude_m", base::CsvColumn("predicted_damping_ratio").nan_as(""),
         base::CsvColumn("dem_damping_ratio").nan_as(""), base::CsvColumn("bare_damping_ratio").nan_as(""),
         base::CsvColumn("dem_final_fraction").nan_as(""), "solve_time_s"});
    std::string checks = "clearance_m,wall_layer_thickness_m," + columns.header() + "\n";
    for (const auto& c : s.candidates)
      for (const auto& check : c.checks)
        checks += base::format_number(c.clearance_m, 10) + "," + base::format_number(c.wall_layer_thickness_m, 10) + "," +
                  columns.row(check) + "\n";
    out.add("clearance_search_checks.csv", checks);
  }
  const double chosen_mm = s.candidates[s.chosen].clearance_m * 1e3;
  std::ostringstream gp;
  gp << "# the added damping ratio of the target mode against the clearance h (calibrated beds), one curve per lining;\n"
     << "# pdamp modes, clearance_search; run: gnuplot clearance_search.gp\n"
     << "set datafile separator ','\nset logscale x\nset grid\nset key below\n"
     << "set xlabel 'clearance h / mm'\nset ylabel 'added damping ratio {/Symbol z}_{add} of mode "
     << s.settings.mode + 1 << "'\n"
     << "set title " << gnuplot_string(case_name + ": clearance for the damping of mode " + std::to_string(s.settings.mode + 1))
     << " noenhanced\n"
     << "set arrow from " << chosen_mm << ", graph 0 to " << chosen_mm << ", graph 1 nohead lc rgb 'black' dt 2\n"
     << "set label 'chosen' at " << chosen_mm << ", graph 0.97 left offset 0.5,0\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'clearance_search.svg' : 'clearance_search.png'\n"
     << "  plot ";
  // One curve per lining (the search's thicknesses; one curve without them), its rows picked
  // by the thickness column within a relative 1e-6 (the CSV's ten digits).
  const std::string objective =
      s.settings.objective == case_file::ModesClearanceSearch::Objective::kWorst ? "smallest" : "mean";
  std::vector<double> linings;
  for (const auto& c : s.candidates)  // a lining none of whose candidates was run has no curve
    if (c.buildable && std::find(linings.begin(), linings.end(), c.wall_layer_thickness_m) == linings.end())
      linings.push_back(c.wall_layer_thickness_m);
  const char* colours[] = {"black", "dark-green", "orange", "purple", "brown", "dark-cyan"};
  const bool lined = !s.settings.wall_layer_thicknesses_m.empty();
  for (std::size_t i = 0; i < linings.size(); ++i) {
    const std::string t = base::format_number(linings[i], 10);
    const std::string pick = lined ? "abs($3 - " + t + ") <= 1e-6 * " + t : "1";
    gp << (i == 0 ? "" : ", \\\n       ") << "'clearance_search.csv' using (" << pick
       << " ? $1*1000 : 1/0):6 every ::1 with linespoints lw 2 pt 7 lc rgb '" << colours[i % 6] << "' title '" << objective
       << " over the strokes (calibrated)"
       << (lined ? ", lining " + base::format_number(linings[i] * 1e3, 4) + " mm" : std::string()) << "'";
  }
  if (s.verified)
    gp << ", \\\n       'clearance_search.csv' using ($1*1000):7 every ::1 with points pt 6 ps 1.5 lc rgb 'blue' "
          "title 'mean over the checked decays, calibrated', \\\n"
          "       '' using ($1*1000):8 every ::1 with points pt 7 ps 1.5 lc rgb 'red' title 'the same, DEM in the loop'";
  gp << "\n}\n";
  return out.add_plot("clearance_search.gp", gp.str(), {"clearance_search.png", "clearance_search.svg"});
}

}  // namespace

Warnings write_files(OutputDir& out, const tasks::ModesResult& m) {
  ModeTable table;
  for (Eigen::Index j = 0; j < m.mode_count; ++j) {
    table.frequency_hz.push_back(m.frequencies_with_containers_hz[j]);
    table.bare_frequency_hz.push_back(m.modal.natural_frequencies_hz[j]);
    table.damping_ratio.push_back(m.modal.damping_ratios[j]);
  }
  table.damper_names = m.damper_names;
  table.mass_ratio = m.mass_ratio;
  table.points = m.modal.points;
  write_modes_table(out, table);
  if (!m.dem_checks.empty()) {
    const base::CsvTable<tasks::ModeDecayCheck> columns(
        {"mode", "frequency_hz", "damper_amplitude_m", base::CsvColumn("predicted_damping_ratio").nan_as(""),
         base::CsvColumn("dem_damping_ratio").nan_as(""), base::CsvColumn("bare_damping_ratio").nan_as(""),
         base::CsvColumn("dem_final_fraction").nan_as(""), "solve_time_s"});
    std::string csv = columns.header() + "\n";
    for (const auto& check : m.dem_checks) csv += columns.row(check) + "\n";
    out.add("dem_check.csv", csv);
  }
  Warnings warnings = write_backbone_files(out, m.backbones, m.layer_names,
                                          m.case_name + ": backbones (" + std::string(case_file::to_string(m.method)) + ")",
                                          m.dem_checks.empty() ? "" : "dem_check.csv");
  if (m.clearance_search) append(warnings, clearance_search_files(out, m.case_name, *m.clearance_search));
  return warnings;
}

namespace {

std::string csv_name(const std::string& name) { return safe_file_name(name); }

Warnings stepped_sine_files(OutputDir& out, const tasks::FrfResult& r) {
  const auto& s = *r.stepped;
  const auto& names = s.damper_names;
  std::vector<std::string> outputs;
  for (const auto& d : names) outputs.push_back(csv_name(d));
  // Per damper its magnitude and phase; the first site's spread and its bed's measures.
  const base::CsvTable<st::SteppedSinePoint> table(
      {"sweep", "frequency_hz", {"magnitude", "phase_deg"},
       base::CsvColumn("magnitude_spread").nan_as("0").named_for_first_output(),
       base::CsvColumn("magnitude_standard_error").nan_as("0").named_for_first_output(),
       base::CsvColumn("bed_eta_star").first_output_only(),
       base::CsvColumn("bed_apparent_mass_fraction").first_output_only(), "energy_error", "transient_periods", "stable",
       "steps", "time_step_s", "converged", "periods", base::CsvColumn("convergence/max_relative_change").nan_as(""),
       base::CsvColumn("convergence/relative_drift").nan_as(""),
       base::CsvColumn("convergence/relative_spread").nan_as("")},
      outputs);
  std::string csv = table.header() + "\n";
  for (const auto& branch : s.branches)
    for (const st::SteppedSinePoint* p : st::stepped_sine_peak(branch).ascending) csv += table.row(*p) + "\n";
  out.add("frf_dem.csv", csv);
  return write_frf_dem_plot(out, names, tasks::magnitude_label(r), r.case_name + ": stepped-sine DEM co-simulation");
}

Warnings linear_sweep_files(OutputDir& out, const tasks::FrfResult& r) {
  const auto& l = *r.linear;
  const auto& names = l.damper_names;
  std::vector<std::string> outputs;
  for (const auto& d : names) outputs.push_back(csv_name(d));
  const base::CsvTable<st::CosimulationSweepCycle> table({"time_s", "frequency_hz", {"magnitude", "phase_deg"},
                                                           base::CsvColumn("bed_eta_star").first_output_only(),
                                                           base::CsvColumn("bed_apparent_mass_fraction").first_output_only()},
                                                          outputs);
  std::string csv = table.header("sweep") + "\n";
  for (const auto& s : l.sweeps)
    for (const auto& cycle : s.cycles) csv += table.row(cycle, st::to_string(s.sweep)) + "\n";
  out.add("frf_dem_sweep.csv", csv);
  return write_frf_dem_sweep_plot(out, names, tasks::magnitude_label(r), r.case_name + ": linear-sweep DEM co-simulation");
}

Warnings compare_files(OutputDir& out, const tasks::FrfResult& r) {
  std::vector<CompareDemPoint> dem_points;
  for (const auto& branch : r.stepped->branches)
    for (const st::SteppedSinePoint* p : st::stepped_sine_peak(branch).ascending)
      dem_points.push_back(
          {p->frequency_hz, p->magnitude.front(), std::isfinite(p->spread) ? p->spread : 0.0, std::string(st::to_string(branch.sweep)), p->converged});
  return write_frf_compare_files(out, r.harmonic->response, r.field ? &r.field->response : nullptr, dem_points,
                                 tasks::magnitude_label(r),
                                 r.case_name + (r.field ? ": formulas, field and DEM" : ": formulas and DEM (no field)"));
}

}  // namespace

Warnings write_files(OutputDir& out, const tasks::FrfResult& r) {
  switch (r.method) {
    case tasks::FrfMethod::kFormulas:
    case tasks::FrfMethod::kField:
      return write_frf_files(out, r.harmonic->response, r.harmonic->damper_names, tasks::magnitude_label(r),
                             r.case_name + ": frequency response (" +
                                 std::string(case_file::to_string(r.harmonic->method)) + ")");
    case tasks::FrfMethod::kDem:
      write_frf_without_beds_csv(out, *r.without_beds);
      return r.linear ? linear_sweep_files(out, r) : stepped_sine_files(out, r);
    case tasks::FrfMethod::kCompare: return compare_files(out, r);
  }
  return {};
}

Warnings write_files(OutputDir& out, const tasks::DecayResult& r) {
  write_without_beds_csv(out, r.without_beds);
  if (r.method != tasks::DecayMethod::kDem)
    return write_decay_files(out, r.decay, r.damper_names,
                             r.case_name + ": free decay (" +
                                 std::string(r.method == tasks::DecayMethod::kField ? "field" : "formulas") + ")");
  const auto& decay = r.dem;
  const auto& h = decay.cosimulation.history;
  std::ostringstream csv;
  csv.precision(10);
  csv << "time_s";
  for (const auto& d : r.damper_names) csv << ",site_displacement_m_" << csv_name(d);
  csv << ",envelope_m";
  for (Eigen::Index j = 0; j < r.modes; ++j) csv << ",q_mode" << j + 1;
  for (const auto& d : r.damper_names) csv << ",site_rotation_rad_" << csv_name(d);
  for (const auto& d : r.damper_names) csv << ",bed_force_n_" << csv_name(d);
  csv << '\n';
  for (std::size_t s = 0; s < h.time_s.size(); ++s) {
    const auto row = static_cast<Eigen::Index>(s);
    csv << h.time_s[s];
    for (Eigen::Index d = 0; d < h.site_displacement_m.cols(); ++d) csv << ',' << h.site_displacement_m(row, d);
    csv << ',' << decay.settling.sample_envelope_m[s];
    for (Eigen::Index j = 0; j < h.modal_displacements.cols(); ++j) csv << ',' << h.modal_displacements(row, j);
    for (Eigen::Index d = 0; d < h.site_rotation_rad.cols(); ++d) csv << ',' << h.site_rotation_rad(row, d);
    for (Eigen::Index d = 0; d < h.container_load_n.cols(); ++d) csv << ',' << h.container_load_n(row, d);
    csv << '\n';
  }
  out.add("decay_dem.csv", csv.str());
  // Every bed's ParaView series (--snapshots): particles_<damper>.pvd, container_<damper>.pvd.
  for (std::size_t d = 0; d < r.damper_names.size() && d < r.bed_worlds.size(); ++d) {
    std::vector<const dem_reference::ParticleSnapshot*> particles;
    std::vector<dem_reference::Vec3> containers;
    for (const auto& beds : decay.cosimulation.bed_snapshots) {
      particles.push_back(&beds[d].particles);
      containers.push_back(beds[d].container_position_m);
    }
    const std::string suffix = std::string(1, '_').append(csv_name(r.damper_names[d]));  // GCC 12: no -Wrestrict on "_" + s
    write_paraview_series(out, suffix, r.bed_worlds[d], particles, containers);
  }
  return write_decay_dem_plot(out, decay.static_offset_m, decay.threshold_m, decay.settling.settling_time_s,
                              r.damper_names.size(), r.case_name + ": free decay (dem co-simulation)");
}

namespace {

/// designs.csv (one row per design and layer), decay_compare.csv and its plot.
Warnings design_files(OutputDir& out, const tasks::FillingRatiosResult& res) {
  const auto& r = res.optimum;
  const base::CsvTable<opt::LayerDesign> layer_columns(
      {"slabs", "particles", "filling_ratio", "volume_fraction", "clearance_m", "bed_mass_kg"});
  const base::CsvTable<opt::FillingDesign> design_columns({base::CsvColumn("settling_time_s").nan_as("-1"), "objective"});
  std::string csv = layer_columns.header("design,layer") + "," + design_columns.header() + "\n";
  const std::vector<std::pair<std::string, const opt::FillingDesign*>> designs = {
      {"chosen", &r.chosen},   {"relaxed", &r.relaxed}, {"baseline", &r.baseline},
      {"initial", &r.initial}, {"bare", &r.bare},       {"same_mass", &r.same_mass}};
  for (const auto& [name, d] : designs)
    for (const auto& l : d->layers) csv += layer_columns.row(l, name + "," + l.name) + "," + design_columns.row(*d) + "\n";
  out.add("designs.csv", csv);

  const auto& runs = res.comparison.decays;
  std::ostringstream env;
  env.precision(10);
  env << "time_s,envelope_chosen_m,envelope_baseline_m,envelope_initial_m,threshold_m,envelope_without_particles_m\n";
  for (std::size_t i = 0; i < runs.front().samples.size(); ++i)
    env << runs[0].samples[i].time_s << ',' << runs[0].samples[i].threshold_measure_m << ','
        << runs[1].samples[i].threshold_measure_m << ',' << runs[2].samples[i].threshold_measure_m << ','
        << runs[0].threshold_used_m << ',' << runs[3].samples[i].threshold_measure_m << '\n';
  out.add("decay_compare.csv", env.str());
  std::ostringstream gp;
  gp << "# free-decay envelopes of pdamp optimize (filling ratios); run: gnuplot decay_compare.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(res.case_name + ": chosen multi-layer design vs best single layer") << " noenhanced\n"
     << "set xlabel 'time t / s'\nset ylabel 'envelope at the damper site / mm'\nset grid\nset key top right\n"
     << "set logscale y\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'decay_compare.svg' : 'decay_compare.png'\n"
     << "  plot 'decay_compare.csv' using 1:($2*1e3) every ::1 with lines lw 2 lc rgb 'blue' title 'chosen', \\\n"
     << "       '' using 1:($3*1e3) every ::1 with lines lw 2 lc rgb 'red' title 'best single layer', \\\n"
     << "       '' using 1:($4*1e3) every ::1 with lines lw 1 dt 2 lc rgb 'gray40' title 'case start', \\\n"
     << "       '' using 1:($6*1e3) every ::1 with lines lw 1.5 dt 4 lc rgb 'dark-orange' title 'without particles', \\\n"
     << "       '' using 1:($5*1e3) every ::1 with lines lw 1 dt 3 lc rgb 'black' title 'threshold'\n"
     << "}\n";
  return out.add_plot("decay_compare.gp", gp.str(), {"decay_compare.png", "decay_compare.svg"});
}

/// verify_decay.csv (one block per design, chosen then baseline, separated by two blank
/// lines for gnuplot's `index`, one header: the DEM's site displacement and envelope and
/// the predicted envelope at the same instants) and its plot.
/// `predicted_by`: what predicted ("closed forms", "calibrated beds").
Warnings verification_files(OutputDir& out, const std::string& case_name, const tasks::Verification& v,
                            const std::string& predicted_by) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "design,time_s,site_displacement_m,dem_envelope_m,predicted_envelope_m,threshold_m\n";
  for (std::size_t k = 0; k < v.designs.size(); ++k) {
    const auto& d = v.designs[k];
    if (k > 0) csv << "\n\n";
    for (std::size_t i = 0; i < d.dem.time_s.size(); ++i)
      csv << d.name << ',' << d.dem.time_s[i] << ',' << d.dem.site_displacement_m[i] << ','
          << d.dem.settling.sample_envelope_m[i] << ',' << (i < d.predicted_envelope_m.size() ? d.predicted_envelope_m[i] : NAN)
          << ',' << d.dem.threshold_m << '\n';
  }
  out.add("verify_decay.csv", csv.str());
  std::ostringstream gp;
  gp << "# DEM verification of pdamp optimize: envelopes, DEM against the " << predicted_by
     << "; run: gnuplot verify_decay.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(case_name + ": DEM verification (DEM in the loop vs " + predicted_by + ")")
     << " noenhanced\n"
     << "set xlabel 'time t / s'\nset ylabel 'envelope at the damper site / mm'\nset grid\nset key top right\n"
     << "set logscale y\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'verify_decay.svg' : 'verify_decay.png'\n"
     << "  plot 'verify_decay.csv' index 0 using 2:($4*1e3) every ::1 with lines lw 2 lc rgb 'blue' title 'chosen, DEM', \\\n"
     << "       '' index 0 using 2:($5*1e3) every ::1 with lines lw 1 dt 2 lc rgb 'blue' title "
     << gnuplot_string("chosen, " + predicted_by) << ", \\\n"
     << "       '' index 1 using 2:($4*1e3) every ::1 with lines lw 2 lc rgb 'red' title 'best single layer, DEM', \\\n"
     << "       '' index 1 using 2:($5*1e3) every ::1 with lines lw 1 dt 2 lc rgb 'red' title "
     << gnuplot_string("best single layer, " + predicted_by) << ", \\\n"
     << "       '' index 0 using 2:($6*1e3) every ::1 with lines lw 1 dt 3 lc rgb 'black' title 'threshold', \\\n"
     // Without particles (linear: exact by the closed forms), from decay_compare.csv beside it.
     << "       'decay_compare.csv' using 1:($6*1e3) every ::1 with lines lw 1.5 dt 4 lc rgb 'dark-orange' "
        "title 'without particles'\n"
     << "}\n";
  return out.add_plot("verify_decay.gp", gp.str(), {"verify_decay.png", "verify_decay.svg"});
}

}  // namespace

Warnings write_files(OutputDir& out, const tasks::FillingRatiosResult& res) {
  Warnings warnings = design_files(out, res);
  if (res.verification)
    append(warnings, verification_files(out, res.case_name, *res.verification,
                                        res.calibration ? "calibrated beds" : "closed forms"));
  return warnings;
}

Warnings write_files(OutputDir& out, const tasks::PlacementStudy& study) {
  const auto& r = study.result;
  const bool beam = study.beam;
  const base::CsvTable<opt::PlacementPoint> site_columns({"site", "position_m", "objective"});
  const base::CsvTable<opt::ModeAtSite> mode_columns(
      {"frequency_hz=natural_frequency_hz", "damper_amplitude_m", "eta_star", "added_damping_ratio",
       base::CsvColumn("rotation_ratio").nan_as("-1")});
  std::string csv = site_columns.header();
  for (const auto& m : r.best.modes) csv.append(",").append(mode_columns.header({}, "mode" + std::to_string(m.mode + 1) + "_"));
  csv += "\n";
  for (const auto& p : r.scan) {
    csv += site_columns.row(p);
    for (const auto& m : p.modes) csv.append(",").append(mode_columns.row(m));
    csv += "\n";
  }
  out.add("placement.csv", csv);

  std::ostringstream gp;
  gp << "# added damping against the damper's site (pdamp optimize, task placement); run: gnuplot placement.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(study.case_name + ": damper placement") << " noenhanced\n"
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
     << gnuplot_string(study.objective == opt::PlacementObjective::kWorstMode ? "objective (worst mode)"
                                                                              : "objective (weighted mean)");
  for (std::size_t k = 0; k < r.best.modes.size(); ++k) {
    const int column = 4 + 5 * static_cast<int>(k) + 3;  // modeN_added_damping_ratio
    gp << ", \\\n       '' using " << x << ":($" << column << "*100) every ::1 " << style << " lw 2 title "
       << gnuplot_string("mode " + std::to_string(r.best.modes[k].mode + 1));
  }
  gp << "\n}\n";
  return out.add_plot("placement.gp", gp.str(), {"placement.png", "placement.svg"});
}

namespace {

/// The predicted curve of one clearance: per frequency the largest |X/U| that is not
/// unstable, or the state held at a jump (what the sizing's objective takes).
void predicted_curve(std::ostringstream& csv, const std::string& clearance_mm, const st::FrequencyResponse& r) {
  for (const auto& p : r.points) {
    double largest = -1.0;
    for (const auto& root : p.roots)
      if (root.stability != st::Stability::kUnstable && !root.outputs.empty())
        largest = std::max(largest, std::abs(root.outputs.front()));
    for (const auto& held : p.held_at_jump)
      if (!held.outputs.empty()) largest = std::max(largest, std::abs(held.outputs.front()));
    if (largest >= 0.0) csv << clearance_mm << ",formulas," << p.frequency_hz << ',' << largest << ",0,1\n";
  }
}

Warnings clearance_verify_files(OutputDir& out, const tasks::ClearanceStudy& study, const tasks::ClearanceVerification& v) {
  const base::CsvTable<tasks::ClearanceCheck> check_columns(
      {"factor", "clearance_m", base::CsvColumn("predicted_peak").nan_as(""),
       base::CsvColumn("predicted_frequency_hz").nan_as(""), base::CsvColumn("predicted_band_centre_hz").nan_as(""),
       "dem_sweep", "dem_peak", base::CsvColumn("dem_peak_standard_error").nan_as("0"), "dem_frequency_hz",
       "dem_band_centre_hz", base::CsvColumn("peak_relative_difference").nan_as(""),
       base::CsvColumn("band_centre_relative_difference").nan_as(""), "unconverged_points", "solve_time_s",
       "predicted_sweep_peak", "ranking"});
  std::string checks = check_columns.header() + "\n";
  for (const auto& k : v.checks) checks += check_columns.row(k) + "\n";
  out.add("clearance_checks.csv", checks);

  // Two gnuplot data sets per clearance (index 2i: the prediction, 2i+1: the DEM points).
  std::ostringstream csv;
  csv.precision(10);
  csv << "clearance_mm,source,frequency_hz,magnitude,magnitude_spread,converged\n";
  std::string titles;
  for (std::size_t i = 0; i < v.checks.size(); ++i) {
    const auto& k = v.checks[i];
    const std::string mm = base::format_number(k.clearance_m * 1e3, 4);
    titles += (titles.empty() ? "" : " ") + mm;
    if (i > 0) csv << "\n\n";
    predicted_curve(csv, mm, k.formulas.harmonic->response);
    csv << "\n\n";
    for (const auto& branch : k.dem.stepped->branches)
      for (const st::SteppedSinePoint* p : st::stepped_sine_peak(branch).ascending)
        csv << mm << ",dem_" << st::to_string(branch.sweep) << ',' << p->frequency_hz << ',' << p->magnitude.front() << ','
            << (std::isfinite(p->spread) ? p->spread : 0.0) << ',' << (p->converged ? 1 : 0) << '\n';
  }
  out.add("clearance_verify.csv", csv.str());

  std::ostringstream gp;
  gp << "# the chosen clearance and its neighbours: the harmonic balance's largest stable |X/U| (lines)\n"
     << "# and the DEM stepped sine up and down (points, error bars: spread over the analysed periods);\n"
     << "# pdamp optimize, task clearance; run: gnuplot clearance_verify.gp\n"
     << "set datafile separator ','\nset logscale y\nset grid\nset key top right\n"
     << "set xlabel 'frequency f / Hz'\nset ylabel 'transmissibility |X/U|'\n"
     << "set title " << gnuplot_string(study.case_name + ": clearance checked by the DEM in the loop") << " noenhanced\n"
     << "h = '" << titles << "'\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,650 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'clearance_verify.svg' : 'clearance_verify.png'\n"
     << "  plot for [i=1:words(h)] 'clearance_verify.csv' index 2*(i-1) using 3:4 with lines lw 2 lc i "
        "title sprintf('h = %s mm, formulas', word(h, i)), \\\n"
     << "       for [i=1:words(h)] '' index 2*i-1 using 3:4:5 with yerrorbars pt 7 ps 0.8 lc i "
        "title sprintf('h = %s mm, DEM', word(h, i))\n"
     << "}\n";
  return out.add_plot("clearance_verify.gp", gp.str(), {"clearance_verify.png", "clearance_verify.svg"});
}

}  // namespace

Warnings write_files(OutputDir& out, const tasks::ClearanceStudy& study) {
  const base::CsvTable<opt::ClearanceResponse> columns({"clearance_m", "peak_transmissibility", "peak_frequency_hz",
                                                        "damper_amplitude_m", "onset_m", "design_stroke_m",
                                                        "held_at_onset"});
  std::string csv = columns.header() + "\n";
  for (const auto& r : study.scan) csv += columns.row(r) + "\n";
  out.add("clearance.csv", csv);

  const double chosen_mm = study.sizing.clearance_m * 1e3, case_mm = study.current.clearance_m * 1e3;
  std::ostringstream gp;
  gp << "# the resonant peak |X/U| against the clearance h (harmonic balance, closed form of the layer);\n"
     << "# pdamp optimize, task clearance; run: gnuplot clearance.gp\n"
     << "set datafile separator ','\nset logscale xy\nset grid\nset key top right\n"
     << "set xlabel 'clearance h / mm'\nset ylabel 'peak transmissibility |X/U|'\n"
     << "set title " << gnuplot_string(study.case_name + ": resonant peak against the clearance") << " noenhanced\n"
     << "set arrow from " << chosen_mm << ", graph 0 to " << chosen_mm << ", graph 1 nohead lc rgb 'black' dt 2\n"
     << "set label 'chosen' at " << chosen_mm << ", graph 0.97 left offset 0.5,0\n"
     << "set arrow from " << case_mm << ", graph 0 to " << case_mm << ", graph 1 nohead lc rgb 'gray50' dt 3\n"
     << "set label 'case' at " << case_mm << ", graph 0.91 left offset 0.5,0 tc rgb 'gray40'\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'clearance.svg' : 'clearance.png'\n"
     << "  plot 'clearance.csv' using ($1*1000):2 every ::1 with linespoints lw 2 pt 7 ps 0.6 lc rgb 'black' "
        "title 'formulas (harmonic balance)'";
  if (study.verification)
    gp << ", \\\n       'clearance_checks.csv' using ($2*1000):7:8 every ::1 with yerrorbars pt 5 ps 1.2 "
          "lc rgb 'red' title 'DEM stepped sine (larger direction)'";
  gp << "\n}\n";
  Warnings warnings;
  if (study.verification) append(warnings, clearance_verify_files(out, study, *study.verification));
  append(warnings, out.add_plot("clearance.gp", gp.str(), {"clearance.png", "clearance.svg"}));
  return warnings;
}

}  // namespace pdamp::report
