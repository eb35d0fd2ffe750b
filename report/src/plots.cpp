// gnuplot pictures: data files and scripts (PNG and SVG), rendered when gnuplot is there.
#include "pdamp/report/plots.hpp"

#include <sstream>

namespace pdamp::report {

namespace fm = formulas;

namespace {

std::string axis_label(surrogate::AxisQuantity q) {
  switch (q) {
    case surrogate::AxisQuantity::kFrequencyHz: return "frequency f / Hz";
    case surrogate::AxisQuantity::kAmplitudeM: return "stroke X / m";
    case surrogate::AxisQuantity::kIntensity: return "intensity {/Symbol G}";
    case surrogate::AxisQuantity::kStrokeOverClearance: return "stroke X / clearance h";
  }
  return "";
}

/// "f = %g Hz" or "{/Symbol G} = %g": the legend of one cut (a gnuplot format).
std::string axis_symbol(surrogate::AxisQuantity q) {
  return q == surrogate::AxisQuantity::kFrequencyHz ? "f = %g Hz" : "{/Symbol G} = %g";
}

/// Short labels of motion modes and regimes for the heat map.
std::string mode_code(const std::string& mode) {
  static const std::vector<std::pair<std::string, std::string>> codes = {
      {"rolling_collect_and_collide", "RC"}, {"bouncing_collect_and_collide", "BC"}, {"collect_and_collide", "CC"},
      {"sub_peak", "SP"},  {"scattering", "SC"}, {"scattered", "SC"}, {"solid_like", "SL"},
      {"local_fluidisation", "LF"}, {"global_fluidisation", "GF"}, {"decoupled", "DC"}};
  for (const auto& [name, code] : codes)
    if (mode == name) return code;
  return "?";
}

/// Most axis-0 nodes drawn as cuts, and most nodes labelled with their motion mode.
constexpr std::size_t kMaxCuts = 12;
constexpr std::size_t kMaxLabelledNodes = 400;

/// An axis end widened by 4% of the axis span, so edge labels of the heat map show.
double padded(const std::vector<double>& values, int side) {
  const double span = values.back() - values.front();
  return side < 0 ? values.front() - 0.04 * span : values.back() + 0.04 * span;
}

}  // namespace

std::vector<std::string> write_eta_curve(OutputDir& out, const std::vector<CurvePoint>& curve,
                                         const fm::OptimumStroke& landmarks, double frequency_hz,
                                         const std::string& title) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "stroke_m,stroke_over_clearance,intensity,eta_star,regime,model_used\n";
  for (const auto& p : curve)
    csv << p.stroke_m << ',' << p.stroke_m / landmarks.clearance_m << ',' << p.loss.intensity << ','
        << p.loss.eta_star << ',' << fm::to_string(p.loss.regime) << ',' << fm::to_string(p.loss.model_used) << '\n';
  out.add("eta_curve.csv", csv.str());

  const double h = landmarks.clearance_m;
  std::ostringstream gp;
  gp << "# eta*(X) of pdamp's closed forms; run: gnuplot eta_curve.gp\n"
     << "set datafile separator ','\n"
     << "set xlabel 'stroke X / clearance h'\nset ylabel 'reduced loss factor {/Symbol h}*'\n"
     << "set title " << gnuplot_string(title + " (h = " + format_number(h * 1e3, 4) + " mm, f = " + format_number(frequency_hz, 4) + " Hz)")
     << " noenhanced\n"
     << "set grid\nset key top right\nset yrange [0:*]\n"
     << "set arrow 1 from " << landmarks.x_onset_m / h << ", graph 0 to " << landmarks.x_onset_m / h
     << ", graph 1 nohead dt 2 lc rgb 'gray40'\n"
     << "set label 1 'onset' at " << landmarks.x_onset_m / h << ", graph 0.95 right offset -0.5,0\n"
     << "set arrow 2 from " << landmarks.x_opt_ideal_m / h << ", graph 0 to " << landmarks.x_opt_ideal_m / h
     << ", graph 1 nohead dt 3 lc rgb 'gray40'\n"
     << "set label 2 'ideal peak' at " << landmarks.x_opt_ideal_m / h << ", graph 0.88 left offset 0.5,0\n"
     << "set arrow 3 from " << landmarks.x_opt_m / h << ", graph 0 to " << landmarks.x_opt_m / h
     << ", graph 1 nohead lw 2 lc rgb 'dark-green'\n"
     << "set label 3 'design' at " << landmarks.x_opt_m / h << ", graph 0.80 left offset 0.5,0 tc rgb 'dark-green'\n"
     << "regime(r) = (stringcolumn(5) eq r) ? $4 : 1/0\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'eta_curve.svg' : 'eta_curve.png'\n"
     << "  plot 'eta_curve.csv' using 2:(regime('collect_and_collide')) with lines lw 2 lc rgb 'blue' title 'collect and collide', \\\n"
     << "       '' using 2:(regime('sub_peak')) with lines lw 2 lc rgb 'orange' title 'sub-peak orbit', \\\n"
     << "       '' using 2:(regime('scattered')) with lines lw 2 dt 4 lc rgb 'red' title 'scattered (fit)'\n"
     << "}\n";
  return out.add_plot("eta_curve.gp", gp.str(), {"eta_curve.png", "eta_curve.svg"});
}

std::vector<std::string> write_force_velocity_plot(OutputDir& out, const std::string& title) {
  std::ostringstream gp;
  gp << "# container force and velocity of a pdamp dem run; run: gnuplot force_velocity.gp\n"
     << "set datafile separator ','\nset key autotitle columnhead\n"
     << "set title " << gnuplot_string(title) << " noenhanced\n"
     << "set xlabel 'time t / s'\nset ylabel 'force on the bed F / N'\nset y2label 'container velocity v / (m/s)'\n"
     << "set ytics nomirror\nset y2tics\nset grid\nset key top right\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 1000,500 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'force_velocity.svg' : 'force_velocity.png'\n"
     << "  plot 'time_series.csv' using 1:4 with lines lw 1.5 lc rgb 'blue' title 'force F', \\\n"
     << "       '' using 1:3 axes x1y2 with lines lw 1.5 lc rgb 'red' title 'velocity v'\n"
     << "}\n";
  return out.add_plot("force_velocity.gp", gp.str(), {"force_velocity.png", "force_velocity.svg"});
}

std::vector<std::string> write_field_pictures(OutputDir& out, const surrogate::EffectiveField& field,
                                              const std::string& case_name, const case_file::DamperSpec& damper) {
  const auto& g = field.grid;
  std::ostringstream table, map;
  table.precision(10);
  map.precision(10);
  table << "axis0,axis1,frequency_hz,amplitude_m,eta_star,eta_star_stderr,e_diss_j,apparent_mass_fraction,motion_mode,status\n";
  map << "# axis0 axis1 eta_star mode_code (blocks of constant axis0 for gnuplot's pm3d)\n";
  for (std::size_t k = 0; k < g.size(); ++k) {
    const auto& p = field.points[k];
    const auto drive = surrogate::drive_point(g, k, field.clearance_m);
    table << g.coordinate0(k) << ',' << g.coordinate1(k) << ',' << drive.frequency_hz << ',' << drive.amplitude_m << ','
          << p.eta_star << ',' << p.eta_star_stderr << ',' << p.e_diss_j << ',' << p.apparent_mass_fraction << ','
          << p.motion_mode << ',' << surrogate::to_string(p.status) << '\n';
    map << g.coordinate0(k) << ' ' << g.coordinate1(k) << ' ' << p.eta_star << ' ' << mode_code(p.motion_mode) << '\n';
    if ((k + 1) % g.axis1.size() == 0) map << '\n';
  }
  out.add("field_table.csv", table.str());
  out.add("field_map.dat", map.str());

  // The cuts: eta* along axis 1 at up to kMaxCuts axis-0 nodes (evenly spread, ends
  // included): more curves are unreadable, and gnuplot reads the data once per curve
  // (10,000 nodes took minutes). Their field points and the closed form, finely sampled.
  std::vector<std::size_t> cut_nodes;
  const std::size_t n0 = g.axis0.size();
  const std::size_t cuts_count = std::min(n0, kMaxCuts);
  for (std::size_t j = 0; j < cuts_count; ++j) cut_nodes.push_back(cuts_count == 1 ? 0 : j * (n0 - 1) / (cuts_count - 1));
  std::ostringstream formula, points;
  formula.precision(10);
  points.precision(10);
  formula << "axis0,axis1,eta_star_formula\n";
  points << "axis0,axis1,eta_star,eta_star_stderr\n";
  const double a1 = g.axis1.values.front(), b1 = g.axis1.values.back();
  for (const std::size_t i0 : cut_nodes) {
    for (std::size_t i1 = 0; i1 < g.axis1.size(); ++i1) {
      const auto& p = field.points[i0 * g.axis1.size() + i1];
      points << g.axis0.values[i0] << ',' << g.axis1.values[i1] << ',' << p.eta_star << ',' << p.eta_star_stderr << '\n';
    }
    points << "\n\n";
    for (int j = 0; j <= 200; ++j) {
      const double v1 = a1 + (b1 - a1) * j / 200.0;
      surrogate::Grid one{{g.axis0.quantity, g.axis0.spacing, {g.axis0.values[i0]}}, {g.axis1.quantity, g.axis1.spacing, {v1}}};
      const auto drive = surrogate::drive_point(one, 0, field.clearance_m);
      const auto loss = fm::reduced_loss_factor(damper.model, field.clearance_m, drive.amplitude_m, drive.frequency_hz,
                                                case_file::layer_model_options(damper, damper.layers.front()));
      formula << g.axis0.values[i0] << ',' << v1 << ',' << loss.eta_star << '\n';
    }
    formula << "\n\n";
  }
  out.add("field_cuts_formula.csv", formula.str());
  out.add("field_cuts_points.csv", points.str());
  std::string cut_values;
  for (const std::size_t i0 : cut_nodes) cut_values += format_number(g.axis0.values[i0], 10) + " ";

  const std::string source(surrogate::to_string(field.provenance.source));
  std::vector<std::string> warnings;
  std::ostringstream cuts;
  cuts << "# eta* along axis 1 at each axis-0 node: field points (" << source << ") and the closed form\n"
       << "set datafile separator ','\nset grid\nset key outside right\n"
       << "set xlabel '" << axis_label(g.axis1.quantity) << "'\nset ylabel 'reduced loss factor {/Symbol h}*'\n"
       << "set title " << gnuplot_string(case_name + ": effective field (" + source + ") and closed form") << " noenhanced\n"
       << "set yrange [0:*]\n"
       << "do for [t in 'pngcairo svg'] {\n"
       << "  set terminal t size 1000,600 enhanced font 'Sans,11'\n"
       << "  set output (t eq 'svg') ? 'field_cuts.svg' : 'field_cuts.png'\n"
       << "  plot for [i=0:" << cut_nodes.size() - 1 << "] 'field_cuts_formula.csv' index i using 2:3 with lines dt 2 lw 1.5 lc i+1 "
       << "title sprintf('closed form, " << axis_symbol(g.axis0.quantity) << "', word('" << cut_values << "', i+1)+0), \\\n"
       << "       for [i=0:" << cut_nodes.size() - 1 << "] 'field_cuts_points.csv' index i using 2:3:4 with yerrorlines pt 7 lw 2 "
       << "lc i+1 title sprintf('" << source << ", " << axis_symbol(g.axis0.quantity) << "', word('" << cut_values
       << "', i+1)+0)\n}\n";
  for (auto& w : out.add_plot("field_cuts.gp", cuts.str(), {"field_cuts.png", "field_cuts.svg"})) warnings.push_back(w);

  if (g.axis0.size() >= 2 && g.axis1.size() >= 2) {
    std::ostringstream heat;
    heat << "# heat map of eta* over the two axes, motion modes marked (" << source << ")\n"
         << "set view map\nset pm3d map interpolate 0,0\nset palette rgb 33,13,10\n"
         << "set xlabel '" << axis_label(g.axis0.quantity) << "'\nset ylabel '" << axis_label(g.axis1.quantity) << "'\n"
         << "set cblabel 'reduced loss factor {/Symbol h}*'\n"
         << "set title " << gnuplot_string(case_name + ": effective field (" + source + ")") << " noenhanced\n"
         << "set label 1 'RC/BC rolling/bouncing collect-and-collide, SP sub-peak orbit, SC scattered, SL solid-like, "
            "LF/GF local/global fluidisation, DC decoupled' at screen 0.5, 0.02 center font ',9'\n"
         << "set bmargin 5\n"
         << "set xrange [" << padded(g.axis0.values, -1) << ":" << padded(g.axis0.values, 1) << "]\n"
         << "set yrange [" << padded(g.axis1.values, -1) << ":" << padded(g.axis1.values, 1) << "]\n"
         << "do for [t in 'pngcairo svg'] {\n"
         << "  set terminal t size 1000,700 enhanced font 'Sans,11'\n"
         << "  set output (t eq 'svg') ? 'field_map.svg' : 'field_map.png'\n"
         << "  splot 'field_map.dat' using 1:2:3 with pm3d notitle"
         // Mode labels on every node only while they can be read (and drawn quickly).
         << (g.size() <= kMaxLabelledNodes ? ", '' using 1:2:3:4 with labels tc rgb 'black' font ',10' notitle" : "") << "\n"
         << "}\n";
    for (auto& w : out.add_plot("field_map.gp", heat.str(), {"field_map.png", "field_map.svg"})) warnings.push_back(w);
  }
  return warnings;
}

}  // namespace pdamp::report
