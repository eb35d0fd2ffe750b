// CSV tables and gnuplot pictures of pdamp modes, frf and decay (PNG and SVG, rendered
// when gnuplot is there; the scripts stay with the data either way).
#include "pdamp/report/structure_plots.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <sstream>

namespace pdamp::report {

namespace {

namespace st = structure;

constexpr double kRadToDeg = 57.29577951308232;

/// Line colours of the per-mode and per-output curves, cycled.
const char* colour(std::size_t i) {
  static const char* const colours[] = {"blue", "dark-orange", "dark-green", "purple", "brown", "dark-cyan", "red"};
  return colours[i % (sizeof colours / sizeof colours[0])];
}

/// A CSV column label made of a user's name: no comma, quote or newline can break the header.
std::string label(const std::string& name) { return safe_file_name(name); }

/// Most jump frequencies marked in the FRF plot (a case with many would hide the curves).
constexpr std::size_t kMaxJumpMarks = 30;

}  // namespace

void write_modes_table(OutputDir& out, const ModeTable& t) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "mode,frequency_hz,bare_frequency_hz,damping_ratio";
  for (const auto& d : t.damper_names) csv << ",mass_ratio_" << label(d);
  for (const auto& p : t.points) {
    const std::string n = label(p.name);
    csv << ',' << n << "_translation_x," << n << "_translation_y," << n << "_rotation";
  }
  csv << '\n';
  for (std::size_t j = 0; j < t.frequency_hz.size(); ++j) {
    const auto col = static_cast<Eigen::Index>(j);
    csv << j + 1 << ',' << t.frequency_hz[j] << ',' << t.bare_frequency_hz[j] << ',' << t.damping_ratio[j];
    for (Eigen::Index d = 0; d < t.mass_ratio.cols(); ++d) csv << ',' << t.mass_ratio(col, d);
    for (const auto& p : t.points)
      csv << ',' << p.translation(0, col) << ',' << p.translation(1, col) << ',' << p.rotation(col);
    csv << '\n';
  }
  out.add("modes.csv", csv.str());
}

std::vector<std::string> write_backbone_files(OutputDir& out, const std::vector<st::Backbone>& backbones,
                                              const std::vector<std::string>& layer_names, const std::string& title,
                                              const std::string& dem_check_file) {
  std::vector<std::string> files;
  for (const auto& b : backbones) {
    std::ostringstream csv;
    csv.precision(10);
    csv << "damper_amplitude_m,modal_amplitude,natural_frequency_hz,damped_frequency_hz,added_damping_ratio,"
           "structural_damping_ratio,effective_modal_mass_kg,converged";
    for (const auto& l : layer_names) csv << ",eta_star_" << label(l);
    csv << '\n';
    for (const auto& p : b.points) {
      csv << p.damper_amplitude_m << ',' << p.modal_amplitude << ',' << p.natural_frequency_hz << ','
          << p.damped_frequency_hz << ',' << p.added_damping_ratio << ',' << p.structural_damping_ratio << ','
          << p.effective_modal_mass_kg << ',' << (p.converged ? 1 : 0);
      for (double eta : p.layer_eta_star) csv << ',' << eta;
      csv << '\n';
    }
    const std::string name = "backbone_mode" + std::to_string(b.mode + 1) + ".csv";
    out.add(name, csv.str());
    files.push_back(name);
  }
  if (backbones.empty()) return {};
  auto curves = [&](int column) {
    std::ostringstream plot;
    plot << "  plot ";
    for (std::size_t i = 0; i < backbones.size(); ++i)
      plot << (i ? ", \\\n       " : "") << "'" << files[i] << "' using 1:" << column << " with lines lw 2 lc rgb '"
           << colour(i) << "' title 'mode " << backbones[i].mode + 1 << "'";
    plot << "\n";
    return plot.str();
  };
  std::ostringstream gp;
  gp << "# backbones of pdamp modes: added damping ratio and damped natural frequency over the\n"
     << "# reference damper's amplitude; run: gnuplot backbone.gp\n"
     << "set datafile separator ','\nset logscale x\nset autoscale xfix\nset grid\nset key top left\nset format x '%.0e'\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,900 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'backbone.svg' : 'backbone.png'\n"
     << "  set multiplot layout 2,1 title " << gnuplot_string(title) << " noenhanced\n"
     << "  set xlabel 'damper amplitude X / m'\n"
     << "  set ylabel 'added damping ratio {/Symbol z}_{add}'\n"
     << (dem_check_file.empty()
             ? curves(5)
             : curves(5).substr(0, curves(5).size() - 1) + ", \\\n       '" + dem_check_file +
                   "' using 3:4 every ::1 with points pt 6 ps 1.3 lc rgb 'black' title 'decay, loss models', \\\n"
                   "       '' using 3:5 every ::1 with points pt 7 ps 1.3 lc rgb 'red' title 'decay, DEM in the loop'\n")
     << "  set ylabel 'damped natural frequency f / Hz'\n"
     << (backbones.size() > 1 ? "  set logscale y\n" : "")
     << curves(4)
     << "  unset logscale y\n"
     << "  unset multiplot\n"
     << "}\n";
  return out.add_plot("backbone.gp", gp.str(), {"backbone.png", "backbone.svg"});
}

std::vector<std::string> write_frf_files(OutputDir& out, const st::FrequencyResponse& r,
                                         const std::vector<std::string>& damper_names,
                                         const std::string& magnitude_label, const std::string& title) {
  const std::size_t outputs = r.output_names.size();
  std::size_t max_roots = 0, max_held = 0;
  for (const auto& p : r.points) {
    max_roots = std::max(max_roots, p.roots.size());
    max_held = std::max(max_held, p.held_at_jump.size());
  }
  // frf.csv: one row per frequency.
  std::ostringstream csv;
  csv.precision(10);
  csv << "frequency_hz";
  for (const auto& o : r.output_names) csv << ",linear_magnitude_" << label(o) << ",linear_phase_deg_" << label(o);
  csv << ",roots,held_at_jump,converged";
  for (std::size_t k = 0; k < max_roots; ++k) {
    const std::string root = "root" + std::to_string(k + 1) + "_";
    csv << ',' << root << "branch," << root << "stability";
    for (const auto& d : damper_names) csv << ',' << root << "amplitude_m_" << label(d);
    for (const auto& o : r.output_names) csv << ',' << root << "magnitude_" << label(o) << ',' << root << "phase_deg_" << label(o);
  }
  for (std::size_t k = 0; k < max_held; ++k) {
    const std::string held = "held" + std::to_string(k + 1) + "_";
    csv << ',' << held << "amplitude_m," << held << "upper_state_fraction";
    for (const auto& o : r.output_names) csv << ',' << held << "magnitude_" << label(o) << ',' << held << "phase_deg_" << label(o);
  }
  csv << '\n';
  for (const auto& p : r.points) {
    csv << p.frequency_hz;
    for (const auto& y : p.linear_outputs) csv << ',' << std::abs(y) << ',' << std::arg(y) * kRadToDeg;
    csv << ',' << p.roots.size() << ',' << p.held_at_jump.size() << ',' << (p.converged ? 1 : 0);
    for (std::size_t k = 0; k < max_roots; ++k) {
      if (k < p.roots.size()) {
        const auto& root = p.roots[k];
        csv << ',' << root.branch_id << ',' << st::to_string(root.stability);
        for (double x : root.damper_amplitudes_m) csv << ',' << x;
        for (const auto& y : root.outputs) csv << ',' << std::abs(y) << ',' << std::arg(y) * kRadToDeg;
      } else {
        csv << std::string(2 + damper_names.size() + 2 * outputs, ',');
      }
    }
    for (std::size_t k = 0; k < max_held; ++k) {
      if (k < p.held_at_jump.size()) {
        const auto& held = p.held_at_jump[k];
        csv << ',' << held.damper_amplitude_m << ',' << held.upper_state_fraction;
        for (const auto& y : held.outputs) csv << ',' << std::abs(y) << ',' << std::arg(y) * kRadToDeg;
      } else {
        csv << std::string(2 + 2 * outputs, ',');
      }
    }
    csv << '\n';
  }
  out.add("frf.csv", csv.str());

  // frf_branches.csv: the roots by branch (ascending frequency), then the held states.
  std::map<int, std::vector<std::pair<double, const st::HarmonicRoot*>>> branches;
  for (const auto& p : r.points)
    for (const auto& root : p.roots) branches[root.branch_id].push_back({p.frequency_hz, &root});
  std::ostringstream br;
  br.precision(10);
  br << "branch,frequency_hz,stability";
  for (const auto& d : damper_names) br << ",amplitude_m_" << label(d);
  for (const auto& o : r.output_names) br << ",magnitude_" << label(o);
  for (const auto& o : r.output_names) br << ",phase_deg_" << label(o);
  br << '\n';
  bool first = true;
  for (auto& [id, roots] : branches) {
    std::sort(roots.begin(), roots.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    if (!first) br << '\n';  // a blank line: gnuplot does not join two branches
    first = false;
    for (const auto& [f, root] : roots) {
      br << id << ',' << f << ',' << st::to_string(root->stability);
      for (double x : root->damper_amplitudes_m) br << ',' << x;
      for (const auto& y : root->outputs) br << ',' << std::abs(y);
      for (const auto& y : root->outputs) br << ',' << std::arg(y) * kRadToDeg;
      br << '\n';
    }
  }
  bool any_held = false;
  for (const auto& p : r.points)
    for (const auto& held : p.held_at_jump) {
      if (!any_held && !first) br << '\n';
      any_held = true;
      br << -1 << ',' << p.frequency_hz << ",held_at_jump";
      for (std::size_t d = 0; d < damper_names.size(); ++d) br << ',' << (d == 0 ? held.damper_amplitude_m : std::nan(""));
      for (const auto& y : held.outputs) br << ',' << std::abs(y);
      for (const auto& y : held.outputs) br << ',' << std::arg(y) * kRadToDeg;
      br << '\n';
    }
  out.add("frf_branches.csv", br.str());

  std::ostringstream gp;
  gp << "# frequency response of pdamp frf: with the dampers (every branch; unstable dashed) and\n"
     << "# without the beds (empty containers); run: gnuplot frf.gp\n"
     << "set datafile separator ','\nset logscale y\nset grid\nset key top right\n"
     << "set xlabel 'frequency f / Hz'\nset ylabel " << gnuplot_string(magnitude_label) << " noenhanced\n"
     << "set title " << gnuplot_string(title) << " noenhanced\n";
  std::size_t marks = 0;
  for (const auto& end : r.branch_ends) {
    if (end.kind == st::BranchEnd::Kind::kStrokeRange || marks >= kMaxJumpMarks) continue;
    ++marks;
    gp << "set arrow " << marks << " from " << end.frequency_hz << ", graph 0 to " << end.frequency_hz
       << ", graph 1 nohead dt 3 lc rgb 'gray40'\n"
       << "set label " << marks << " '" << (end.kind == st::BranchEnd::Kind::kFold ? "fold" : "jump") << "' at "
       << end.frequency_hz << ", graph " << (marks % 2 ? 0.97 : 0.92) << " center font ',8' tc rgb 'gray30'\n";
  }
  // Magnitude over phase, one x axis (as NLvib and test-rig software show an FRF). The
  // phase of the output against the excitation, deg, in (-180, 180].
  gp << "state(s, c) = (stringcolumn(3) eq s) ? column(c) : 1/0\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,900 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'frf.svg' : 'frf.png'\n"
     << "  set multiplot layout 2,1\n  set lmargin 12\n"
     << "  set size 1,0.62\n  set origin 0,0.38\n  set logscale y\n  unset xlabel\n"
     << "  plot ";
  const std::size_t first_magnitude = 4 + damper_names.size();
  const auto curves = [&](std::size_t linear_column, std::size_t first_column) {
    for (std::size_t o = 0; o < outputs; ++o) {
      const std::string name = outputs > 1 ? " (" + r.output_names[o] + ")" : "";
      const std::size_t c = first_column + o;
      gp << (o ? ", \\\n       " : "") << "'frf.csv' using 1:" << linear_column + 2 * o << " with lines lw 1.5 dt 4 lc rgb '"
         << colour(o) << "' title " << gnuplot_string("without beds" + name) << " noenhanced, \\\n"
         << "       'frf_branches.csv' using 2:(state('stable', " << c << ")) with lines lw 2 lc rgb '" << colour(o)
         << "' title " << gnuplot_string("with dampers, stable" + name) << " noenhanced, \\\n"
         << "       '' using 2:(state('unstable', " << c << ")) with lines lw 2 dt 2 lc rgb '" << colour(o)
         << "' title " << gnuplot_string("unstable" + name) << " noenhanced, \\\n"
         << "       '' using 2:(state('marginal', " << c << ")) with points pt 6 ps 0.6 lc rgb '" << colour(o)
         << "' notitle";
      if (any_held)
        gp << ", \\\n       '' using 2:(state('held_at_jump', " << c << ")) with points pt 7 ps 0.5 lc rgb '" << colour(o)
           << "' title " << gnuplot_string("held at a jump" + name) << " noenhanced";
    }
    gp << "\n";
  };
  curves(2, first_magnitude);
  gp << "  unset title\n  unset logscale y\n  unset label\n  set key off\n  set xlabel 'frequency f / Hz'\n"
     << "  set ylabel 'phase / deg'\n  set yrange [-180:180]\n  set ytics 90\n"
     << "  set size 1,0.38\n  set origin 0,0\n  plot ";
  curves(3, first_magnitude + outputs);
  gp << "  unset multiplot\n  set yrange [*:*]\n  set ytics autofreq\n  set key top right\n}\n";
  return out.add_plot("frf.gp", gp.str(), {"frf.png", "frf.svg"});
}

void write_frf_without_beds_csv(OutputDir& out, const st::FrequencyResponse& without_beds) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "frequency_hz";
  for (const auto& o : without_beds.output_names) csv << ",magnitude_" << label(o) << ",phase_deg_" << label(o);
  csv << '\n';
  for (const auto& p : without_beds.points) {
    csv << p.frequency_hz;
    for (const auto& y : p.linear_outputs) csv << ',' << std::abs(y) << ',' << std::arg(y) * kRadToDeg;
    csv << '\n';
  }
  out.add(kFrfWithoutBedsCsv, csv.str());
}

void write_without_beds_csv(OutputDir& out, const st::FreeDecay& without_beds) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "time_s,envelope_m\n";
  for (const auto& s : without_beds.samples) csv << s.time_s << ',' << s.threshold_measure_m << '\n';
  out.add(kWithoutBedsCsv, csv.str());
}

std::vector<std::string> write_decay_files(OutputDir& out, const st::FreeDecay& decay,
                                           const std::vector<std::string>& damper_names, const std::string& title) {
  const Eigen::Index modes = decay.samples.empty() ? 0 : decay.samples.front().modal_amplitudes.size();
  std::ostringstream csv;
  csv.precision(10);
  csv << "time_s,envelope_m";
  for (Eigen::Index j = 0; j < modes; ++j) csv << ",amplitude_mode" << j + 1;
  for (const auto& d : damper_names) csv << ",damper_amplitude_m_" << label(d);
  csv << ",mechanical_energy_j,structural_dissipated_energy_j";
  for (const auto& l : decay.layer_names) csv << ",dissipated_energy_j_" << label(l);
  for (const auto& l : decay.layer_names) csv << ",power_w_" << label(l);
  csv << '\n';
  for (const auto& s : decay.samples) {
    csv << s.time_s << ',' << s.threshold_measure_m;
    for (Eigen::Index j = 0; j < modes; ++j) csv << ',' << s.modal_amplitudes[j];
    for (double x : s.damper_amplitudes_m) csv << ',' << x;
    csv << ',' << s.mechanical_energy_j << ',' << s.structural_dissipated_energy_j;
    for (double e : s.layer_dissipated_energy_j) csv << ',' << e;
    for (double p : s.layer_power_w) csv << ',' << p;
    csv << '\n';
  }
  out.add("decay.csv", csv.str());

  const std::size_t energy_column = 3 + static_cast<std::size_t>(modes) + damper_names.size();  // mechanical energy
  std::ostringstream gp;
  gp << "# free decay of pdamp decay: envelope with threshold and settling time, and the energy\n"
     << "# each layer has dissipated; run: gnuplot decay.gp\n"
     << "set datafile separator ','\nset grid\n";
  gp << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,900 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'decay.svg' : 'decay.png'\n"
     << "  set multiplot layout 2,1 title " << gnuplot_string(title) << " noenhanced\n"
     << "  set logscale y\n  set key top right\n"
     << "  set xlabel 'time t / s'\n  set ylabel 'envelope at the threshold point / m'\n"
     << "  set arrow 1 from graph 0, first " << decay.threshold_used_m << " to graph 1, first " << decay.threshold_used_m
     << " nohead dt 2 lc rgb 'red'\n"
     << "  set label 1 'threshold' at graph 0.99, first " << decay.threshold_used_m
     << " right offset 0,0.7 tc rgb 'red'\n";
  if (std::isfinite(decay.settling_time_s))
    gp << "  set arrow 2 from " << decay.settling_time_s << ", graph 0 to " << decay.settling_time_s
       << ", graph 1 nohead lw 2 lc rgb 'dark-green'\n"
       << "  set label 2 " << gnuplot_string("settled: " + format_number(decay.settling_time_s, 4) + " s") << " at "
       << decay.settling_time_s << ", graph 0.9 left offset 0.5,0 tc rgb 'dark-green'\n";
  gp << "  plot 'decay.csv' using 1:2 with lines lw 2 lc rgb 'blue' title 'envelope', \\\n"
     << "       '" << kWithoutBedsCsv << "' using 1:2 with lines lw 1.5 dt 2 lc rgb 'gray40' title 'without particles'\n"
     << "  unset arrow\n  unset label\n  unset logscale y\n  set key top left\n"
     << "  set ylabel 'dissipated energy / J'\n"
     << "  plot 'decay.csv' using 1:" << energy_column + 1 << " with lines lw 1.5 dt 2 lc rgb 'gray40' title 'structure'";
  for (std::size_t l = 0; l < decay.layer_names.size(); ++l)
    gp << ", \\\n       '' using 1:" << energy_column + 2 + l << " with lines lw 2 lc rgb '" << colour(l) << "' title "
       << gnuplot_string(decay.layer_names[l]) << " noenhanced";
  gp << "\n  unset multiplot\n}\n";
  return out.add_plot("decay.gp", gp.str(), {"decay.png", "decay.svg"});
}

std::vector<std::string> write_decay_dem_plot(OutputDir& out, double offset_m, double threshold_m, double settling_time_s,
                                              std::size_t dampers, const std::string& title) {
  const std::size_t envelope_column = 2 + dampers;  // 1-based
  std::ostringstream gp;
  gp.precision(10);
  gp << "# free decay of pdamp decay --method dem: the site displacement of the first damper along its\n"
     << "# drive, the envelope (largest |y - offset| per period) and the threshold; run: gnuplot decay_dem.gp\n"
     << "set datafile separator ','\nset grid\n";
  gp << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'decay_dem.svg' : 'decay_dem.png'\n"
     << "  set title " << gnuplot_string(title) << " noenhanced\n"
     << "  set key top right\n  set xlabel 'time t / s'\n  set ylabel 'site displacement along the drive / m'\n"
     << "  set arrow 1 from graph 0, first " << offset_m + threshold_m << " to graph 1, first " << offset_m + threshold_m
     << " nohead dt 2 lc rgb 'red'\n"
     << "  set arrow 3 from graph 0, first " << offset_m - threshold_m << " to graph 1, first " << offset_m - threshold_m
     << " nohead dt 2 lc rgb 'red'\n";
  if (std::isfinite(settling_time_s))
    gp << "  set arrow 2 from " << settling_time_s << ", graph 0 to " << settling_time_s
       << ", graph 1 nohead lw 2 lc rgb 'dark-green'\n"
       << "  set label 2 " << gnuplot_string("settled: " + format_number(settling_time_s, 4) + " s") << " at "
       << settling_time_s << ", graph 0.9 left offset 0.5,0 tc rgb 'dark-green'\n";
  gp << "  plot 'decay_dem.csv' using 1:2 with lines lw 1 lc rgb 'blue' title 'site displacement', \\\n"
     << "       '' using 1:(" << offset_m << " + $" << envelope_column << ") with lines lw 2 lc rgb 'dark-orange' title 'envelope', \\\n"
     << "       '' using 1:(" << offset_m << " - $" << envelope_column << ") with lines lw 2 lc rgb 'dark-orange' notitle, \\\n"
     << "       '" << kWithoutBedsCsv << "' using 1:(" << offset_m << " + $2) with lines lw 1.5 dt 2 lc rgb 'gray40' "
     << "title 'envelope without particles', \\\n"
     << "       '' using 1:(" << offset_m << " - $2) with lines lw 1.5 dt 2 lc rgb 'gray40' notitle\n"
     << "  unset arrow\n  unset label\n}\n";
  return out.add_plot("decay_dem.gp", gp.str(), {"decay_dem.png", "decay_dem.svg"});
}

namespace {

/// The DEM plots' curves of the structure without particles (frf_without_particles.csv,
/// one magnitude per damper's site), appended to a plot command.
void without_beds_curves(std::ostream& gp, const std::vector<std::string>& damper_names) {
  for (std::size_t d = 0; d < damper_names.size(); ++d)
    gp << ", \\\n       '" << kFrfWithoutBedsCsv << "' using 1:" << 2 + 2 * d << " every ::1 with lines lw 1.5 dt 4 lc rgb '"
       << colour(d) << "' title " << gnuplot_string(damper_names[d] + ", without particles") << " noenhanced";
}

}  // namespace

std::vector<std::string> write_frf_dem_plot(OutputDir& out, const std::vector<std::string>& damper_names,
                                            const std::string& magnitude_label, const std::string& title) {
  // frf_dem.csv: sweep, frequency_hz, then magnitude and phase per damper, then the spread, the
  // standard error, η*, m_app, energy_error, transient_periods, stable, steps, time_step_s, converged.
  const std::size_t spread_column = 3 + 2 * damper_names.size();  // 1-based
  const std::size_t converged_column = spread_column + 9;
  std::ostringstream gp;
  gp << "# stepped-sine frequency response of pdamp frf --method dem (first harmonic at each frequency,\n"
     << "# up and down in frequency; error bars: the spread over the analysed periods); the curves join\n"
     << "# the converged points only, an unconverged point (its transient still changing) is a cross\n"
     << "# off the curve; run: gnuplot frf_dem.gp\n"
     << "set datafile separator ','\nset grid\n"
     << "ok(s, c) = (stringcolumn(1) eq s && column(" << converged_column << ") == 1) ? column(c) : 1/0\n"
     << "bad(s, c) = (stringcolumn(1) eq s && column(" << converged_column << ") == 0) ? column(c) : 1/0\n";
  gp << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'frf_dem.svg' : 'frf_dem.png'\n"
     << "  set title " << gnuplot_string(title) << " noenhanced\n"
     << "  set logscale y\n  set key top right\n  set xlabel 'frequency / Hz'\n  set ylabel "
     << gnuplot_string(magnitude_label) << " noenhanced\n  plot ";
  // The first damper's points carry the spread as error bars.
  const std::string errorbars = std::string(":").append(std::to_string(spread_column)).append(" with yerrorbars");
  bool first = true;
  for (std::size_t d = 0; d < damper_names.size(); ++d)
    for (const char* sweep : {"up", "down"}) {
      const bool up = std::string(sweep) == "up";
      const std::string column = std::to_string(3 + 2 * d);
      const std::string name = gnuplot_string(damper_names[d] + ", " + sweep);
      if (!first) gp << ", \\\n       ";
      first = false;
      gp << "'frf_dem.csv' using 2:(ok('" << sweep << "', " << column << "))"
         << (d == 0 ? errorbars : std::string(" with points")) << " pt "
         << (up ? 7 : 6) << " lc rgb '" << colour(d) << "' notitle, '' using 2:(ok('" << sweep << "', " << column
         << ")) with lines lw 2 dt " << (up ? 1 : 2) << " lc rgb '" << colour(d) << "' title " << name << " noenhanced"
         << ", '' using 2:(bad('" << sweep << "', " << column << ")) with points pt 2 ps 1.5 lc rgb '" << colour(d)
         << "' title " << gnuplot_string(damper_names[d] + ", " + sweep + ": unconverged (not on the curve)")
         << " noenhanced";
    }
  without_beds_curves(gp, damper_names);
  gp << "\n}\n";
  return out.add_plot("frf_dem.gp", gp.str(), {"frf_dem.png", "frf_dem.svg"});
}

std::vector<std::string> write_frf_dem_sweep_plot(OutputDir& out, const std::vector<std::string>& damper_names,
                                                  const std::string& magnitude_label, const std::string& title) {
  // frf_dem_sweep.csv: sweep, time_s, frequency_hz, then magnitude and phase per damper.
  std::ostringstream gp;
  gp << "# linear-sweep frequency response of pdamp frf --method dem --dem-signal linear (first harmonic\n"
     << "# of each drive cycle against its mean frequency; up solid, down dashed); run: gnuplot frf_dem_sweep.gp\n"
     << "set datafile separator ','\nset grid\n"
     << "sel(s, c) = (stringcolumn(1) eq s) ? column(c) : 1/0\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'frf_dem_sweep.svg' : 'frf_dem_sweep.png'\n"
     << "  set title " << gnuplot_string(title) << " noenhanced\n"
     << "  set logscale y\n  set key top right\n  set xlabel 'frequency / Hz'\n  set ylabel "
     << gnuplot_string(magnitude_label) << " noenhanced\n  plot ";
  bool first = true;
  for (std::size_t d = 0; d < damper_names.size(); ++d)
    for (const char* sweep : {"up", "down"}) {
      if (!first) gp << ", \\\n       ";
      first = false;
      gp << "'frf_dem_sweep.csv' using 3:(sel('" << sweep << "', " << 4 + 2 * d << ")) with lines lw 1 dt "
         << (std::string(sweep) == "up" ? 1 : 2) << " lc rgb '" << colour(d) << "' title "
         << gnuplot_string(damper_names[d] + ", " + sweep) << " noenhanced";
    }
  without_beds_curves(gp, damper_names);
  gp << "\n}\n";
  return out.add_plot("frf_dem_sweep.gp", gp.str(), {"frf_dem_sweep.png", "frf_dem_sweep.svg"});
}

std::vector<std::string> write_frf_compare_files(OutputDir& out, const st::FrequencyResponse& formulas,
                                                 const st::FrequencyResponse* field,
                                                 const std::vector<CompareDemPoint>& dem,
                                                 const std::string& magnitude_label, const std::string& title) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "source,branch,frequency_hz,stability,magnitude,magnitude_spread\n";
  bool first = true;
  const auto branches = [&](const st::FrequencyResponse& r, const std::string& source) {
    std::map<int, std::vector<std::pair<double, const st::HarmonicRoot*>>> by_branch;
    for (const auto& p : r.points)
      for (const auto& root : p.roots)
        if (!root.outputs.empty()) by_branch[root.branch_id].push_back({p.frequency_hz, &root});
    for (auto& [id, roots] : by_branch) {
      std::sort(roots.begin(), roots.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      if (!first) csv << '\n';  // a blank line: gnuplot does not join two branches
      first = false;
      for (const auto& [f, root] : roots)
        csv << source << ',' << id << ',' << f << ',' << st::to_string(root->stability) << ','
            << std::abs(root->outputs.front()) << ",0\n";
    }
    // The states held at a jump (where no harmonic-balance root exists, the averaged
    // bed stays at its onset): without them the curve has a gap there.
    bool held_block = false;
    for (const auto& p : r.points)
      for (const auto& held : p.held_at_jump) {
        if (held.outputs.empty()) continue;
        if (!held_block && !first) csv << '\n';
        held_block = true;
        first = false;
        csv << source << ",-1," << p.frequency_hz << ",held_at_jump," << std::abs(held.outputs.front()) << ",0\n";
      }
  };
  branches(formulas, "formulas");
  if (field) branches(*field, "field");
  // The structure without particles (the containers empty), the same for every source.
  if (!first) csv << '\n';
  for (const auto& p : formulas.points)
    if (!p.linear_outputs.empty()) csv << "without_beds,0," << p.frequency_hz << ",linear," << std::abs(p.linear_outputs.front()) << ",0\n";
  csv << '\n';
  for (const auto& p : dem)
    csv << "dem_" << p.sweep << ",0," << p.frequency_hz << (p.converged ? ",dem," : ",dem_unconverged,") << p.magnitude
        << ',' << p.spread << '\n';
  out.add("frf_compare.csv", csv.str());

  std::ostringstream gp;
  gp << "# pdamp frf --compare: the first output by the closed-form loss models (formulas), the\n"
     << "# layers' effective fields (field) and the stepped-sine DEM co-simulation (points, error bars:\n"
     << "# spread over the analysed periods; crosses: unconverged points); unstable harmonic-balance roots\n"
     << "# dashed; run: gnuplot frf_compare.gp\n"
     << "set datafile separator ','\nset logscale y\nset grid\nset key top right\n"
     << "set xlabel 'frequency f / Hz'\nset ylabel " << gnuplot_string(magnitude_label) << " noenhanced\n"
     << "set title " << gnuplot_string(title) << " noenhanced\n"
     << "sel(s, t, c) = (stringcolumn(1) eq s && stringcolumn(4) eq t) ? column(c) : 1/0\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,650 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'frf_compare.svg' : 'frf_compare.png'\n"
     << "  plot 'frf_compare.csv' using 3:(sel('formulas', 'stable', 5)) with lines lw 2 lc rgb '" << colour(0)
     << "' title 'formulas', \\\n"
     << "       '' using 3:(sel('formulas', 'unstable', 5)) with lines lw 2 dt 2 lc rgb '" << colour(0)
     << "' title 'formulas, unstable', \\\n";
  if (field)
    gp << "       '' using 3:(sel('field', 'stable', 5)) with lines lw 2 lc rgb '" << colour(1) << "' title 'field', \\\n"
       << "       '' using 3:(sel('field', 'unstable', 5)) with lines lw 2 dt 2 lc rgb '" << colour(1)
       << "' title 'field, unstable', \\\n";
  gp << "       '' using 3:(sel('formulas', 'held_at_jump', 5)) with points pt 7 ps 0.5 lc rgb '" << colour(0)
     << "' title 'formulas, held at a jump', \\\n";
  if (field)
    gp << "       '' using 3:(sel('field', 'held_at_jump', 5)) with points pt 7 ps 0.5 lc rgb '" << colour(1)
       << "' title 'field, held at a jump', \\\n";
  gp << "       '' using 3:(sel('without_beds', 'linear', 5)) with lines lw 1.5 dt 4 lc rgb 'gray40' title 'without particles', \\\n"
     << "       '' using 3:(sel('dem_up', 'dem', 5)):6 with yerrorbars pt 7 ps 1.2 lc rgb '" << colour(2)
     << "' title 'DEM, stepped sine up', \\\n"
     << "       '' using 3:(sel('dem_down', 'dem', 5)):6 with yerrorbars pt 6 ps 1.2 lc rgb '" << colour(3)
     << "' title 'DEM, stepped sine down', \\\n"
     << "       '' using 3:(sel('dem_up', 'dem_unconverged', 5)) with points pt 2 ps 1.5 lc rgb '" << colour(2)
     << "' title 'DEM up, unconverged', \\\n"
     << "       '' using 3:(sel('dem_down', 'dem_unconverged', 5)) with points pt 2 ps 1.5 lc rgb '" << colour(3)
     << "' title 'DEM down, unconverged'\n}\n";
  return out.add_plot("frf_compare.gp", gp.str(), {"frf_compare.png", "frf_compare.svg"});
}

}  // namespace pdamp::report
