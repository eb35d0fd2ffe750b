// The report's first paragraph: the answer to the question the case asks, in the units a
// damper is built with (g, mm, s), from the result JSON and the resolved case alone.
#include "report_answer.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "pdamp/base/number_text.hpp"

namespace pdamp::report {

namespace {

using nlohmann::json;
using base::format_number;

/// The value at `path` ("a/b/0/c") or null: a missing key is "not known", never an error.
const json& at(const json& object, std::initializer_list<const char*> path) {
  static const json kNull;
  const json* node = &object;
  for (const char* key : path) {
    if (node->is_object() && node->contains(key)) node = &(*node)[key];
    else if (node->is_array() && std::string(key).find_first_not_of("0123456789") == std::string::npos &&
             std::stoul(key) < node->size())
      node = &(*node)[std::stoul(key)];
    else return kNull;
  }
  return *node;
}

bool number(const json& v) { return v.is_number() && std::isfinite(v.get<double>()); }

}  // namespace

std::string three_digits(double value) { return std::isfinite(value) ? format_number(value, 3) : "–"; }
std::string in_mm(const json& metres) { return number(metres) ? three_digits(metres.get<double>() * 1e3) + " mm" : "–"; }
std::string in_g(const json& kilograms) { return number(kilograms) ? three_digits(kilograms.get<double>() * 1e3) + " g" : "–"; }

namespace {

std::string in_s(const json& seconds) { return number(seconds) ? three_digits(seconds.get<double>()) + " s" : "–"; }
std::string plain(const json& v) { return number(v) ? three_digits(v.get<double>()) : v.is_string() ? v.get<std::string>() : "–"; }
/// A name as words: "sub_peak" -> "sub peak".
std::string words(const json& v) {
  std::string text = plain(v);
  for (char& ch : text)
    if (ch == '_') ch = ' ';
  return text;
}
std::string percent(double fraction) { return three_digits(100.0 * fraction) + " %"; }
std::string percent_of(const json& fraction) { return number(fraction) ? percent(fraction.get<double>()) : "–"; }

/// "X times faster" of a settling time t against a reference t_ref (both finite).
std::string times_faster(double t, double t_ref) {
  if (!(t > 0.0) || !(t_ref > 0.0)) return "";
  const double ratio = t_ref / t;
  return ratio >= 1.0 ? three_digits(ratio) + " times faster than" : three_digits(1.0 / ratio) + " times slower than";
}

/// One design's layers: "1 slab (16 spheres, 16.4 g) in wide (clearance 60.0 mm)".
std::string layers_text(const json& design, bool skip_empty) {
  std::vector<std::string> parts;
  for (const auto& l : at(design, {"layers"})) {
    const double slabs = number(at(l, {"slabs"})) ? at(l, {"slabs"}).get<double>() : 0.0;
    if (skip_empty && slabs == 0.0) continue;
    std::ostringstream part;
    part << three_digits(slabs) << (slabs == 1.0 ? " slab" : " slabs") << " (" << plain(at(l, {"particles"})) << " spheres, "
         << in_g(at(l, {"bed_mass_kg"})) << ") in " << plain(at(l, {"name"})) << " (clearance " << in_mm(at(l, {"clearance_m"})) << ")";
    parts.push_back(part.str());
  }
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i == 0 ? "" : i + 1 == parts.size() ? " and " : ", ") + parts[i];
  return out.empty() ? "no particles" : out;
}

/// "settles in 9.59 s" or "does not settle within 20.0 s".
std::string settling_text(const json& time_s, const json& duration_s) {
  return number(time_s) ? "settles in " + in_s(time_s) : "does not settle within " + in_s(duration_s);
}

Answer filling_ratios_answer(const json& r, const json& c) {
  Answer a;
  const json& chosen = at(r, {"designs", "chosen"});
  const json& baseline = at(r, {"designs", "baseline"});
  const json& bare = at(r, {"designs", "bare"});
  const json& task = at(c, {"task"});
  const bool settling = at(r, {"objective", "kind"}) == "settling_time";
  const json& duration = at(task, {"duration_s"});
  std::ostringstream p;
  p << "Fill " << layers_text(chosen, true) << ": " << in_g(at(chosen, {"total_mass_kg"})) << " of particles";
  if (number(at(r, {"mass_budget_kg"}))) p << " of the " << in_g(at(r, {"mass_budget_kg"})) << " allowed";
  p << ". ";
  const json& v = at(r, {"verification"});
  if (settling) {
    const std::string threshold = number(at(task, {"settling_threshold"}))
                                      ? percent(at(task, {"settling_threshold"}).get<double>()) + " of its initial envelope"
                                      : "its threshold";
    p << "Released from the case's initial state, the structure is predicted to settle to " << threshold << " in "
      << in_s(at(chosen, {"settling_time_s"})) << "; the best single layer (" << layers_text(baseline, true) << ") "
      << settling_text(at(baseline, {"settling_time_s"}), duration) << " and without particles the structure "
      << settling_text(at(bare, {"settling_time_s"}), duration) << ". ";
    const json& dem_chosen = at(v, {"designs", "chosen", "dem", "settling_time_s"});
    const json& dem_baseline = at(v, {"designs", "baseline", "dem", "settling_time_s"});
    if (number(dem_chosen)) {
      p << "The DEM in the loop settles the chosen design in " << in_s(dem_chosen);
      if (number(dem_baseline))
        p << ", " << times_faster(dem_chosen.get<double>(), dem_baseline.get<double>()) << " the best single layer ("
          << in_s(dem_baseline) << ")";
      else if (!v.is_null())
        p << "; the best single layer does not settle within " << in_s(at(v, {"duration_s"}));
      p << ". ";
    }
  } else {
    p << "Objective (" << plain(at(r, {"objective", "kind"})) << "): " << plain(at(chosen, {"objective"})) << " "
      << plain(at(r, {"objective", "unit"})) << ", against " << plain(at(baseline, {"objective"}))
      << " for the best single layer and " << plain(at(bare, {"objective"})) << " without particles. ";
  }
  a.paragraphs.push_back(p.str());
  if (v.is_object()) {
    const bool passed = at(v, {"passed"}) == true;
    std::ostringstream verdict;
    verdict << "DEM check: " << (passed ? "PASS" : "FAIL") << ". ";
    std::vector<std::string> failed;
    for (const char* name : {"chosen", "baseline"}) {
      const json& d = at(v, {"designs", name});
      if (d.is_null()) continue;
      if (at(d, {"passed"}) != true) failed.push_back(std::string("the ") + (std::string(name) == "chosen" ? "chosen design" : "best single layer") + " differs from its prediction by more than " + percent_of(at(v, {"tolerance_relative"})));
      if (at(d, {"softening_check", "converged"}) == false)
        failed.push_back(std::string("the ") + name + " design's DEM result changes with stiffer contacts (the softening has not converged)");
    }
    if (at(v, {"ranking", "passed"}) == false) failed.push_back("the DEM does not rank the chosen design ahead of the best single layer");
    if (passed)
      verdict << "The DEM in the loop agrees with the prediction within the case's "
              << percent_of(at(v, {"tolerance_relative"}))
              << ", ranks the chosen design ahead of the best single layer"
              << (at(v, {"designs", "chosen", "softening_check"}).is_object() ? ", and gives the same with stiffer contacts" : "")
              << ": the prediction can be trusted for this design.";
    else {
      verdict << "Do not build on the prediction: ";
      for (std::size_t i = 0; i < failed.size(); ++i) verdict << (i ? "; " : "") << failed[i];
      verdict << ". The DEM's numbers above are the better estimate.";
    }
    a.verdict = verdict.str();
    a.passed = passed;
  } else {
    a.verdict = "Not checked by the DEM (run with the verification to check the prediction).";
  }
  return a;
}

Answer damper_design_answer(const json& r, const json& c) {
  Answer a;
  const json& op = at(r, {"operating_point"});
  const json& opt = at(r, {"optimum"});
  const json& particles = at(c, {"damper", "particles"});
  std::ostringstream p;
  p << "A bed of " << plain(at(particles, {"count"})) << " " << plain(at(particles, {"material"})) << " spheres of "
    << in_mm(at(particles, {"radius_m"})) << " radius (" << in_g(at(r, {"bed_mass_kg"})) << ") with a clearance of "
    << in_mm(at(r, {"clearance_m"})) << " along the drive";
  if (number(at(r, {"sizing", "container_inner_length_along_drive_m"})))
    p << " (container inner length " << in_mm(at(r, {"sizing", "container_inner_length_along_drive_m"})) << ")";
  p << ", shaken at " << plain(at(c, {"excitation", "frequency_hz"})) << " Hz with a stroke of " << in_mm(at(op, {"amplitude_m"}))
    << " (intensity Γ = " << plain(at(op, {"intensity"})) << "), has a reduced loss factor η* = " << plain(at(op, {"eta_star"}))
    << ": it dissipates " << (number(at(op, {"e_diss_j"})) ? three_digits(at(op, {"e_diss_j"}).get<double>() * 1e3) : "–")
    << " mJ per cycle (" << plain(at(op, {"model_used"})) << " collect-and-collide model, state " << words(at(op, {"regime"}))
    << "). For this clearance the best stroke is " << in_mm(at(opt, {"x_opt_m"})) << " (η* = " << plain(at(opt, {"eta_star_at_design"}))
    << ").";
  a.paragraphs.push_back(p.str());
  if (at(r, {"buffer"}).is_object()) {
    const json& b = at(r, {"buffer"});
    a.paragraphs.push_back("Buffered walls: a " + plain(at(b, {"layer_material"})) + " layer " +
                           in_mm(at(b, {"layer_thickness_m"})) + " thick keeps the strain at " +
                           plain(at(b, {"allowable_strain"})) + " in an impact at " + plain(at(b, {"impact_velocity_m_s"})) +
                           " m/s (peak force " + plain(at(b, {"max_force_n"})) + " N, contact " +
                           (number(at(b, {"contact_time_s"})) ? three_digits(at(b, {"contact_time_s"}).get<double>() * 1e3) : "–") +
                           " ms).");
  }
  const json& margin = at(op, {"stroke_over_onset"});
  if (number(margin)) {
    const double s = margin.get<double>();
    a.passed = s >= 1.1;
    a.verdict = s >= 1.0 ? "Margin to the cliff: the stroke is " + three_digits(s) + " times the onset of collect-and-collide (" +
                               in_mm(at(opt, {"x_onset_m"})) + ")" +
                               (s < 1.1 ? ", less than 10 % above it: a smaller stroke in service drops η* to the scattered state's." : ".")
                         : "Below the cliff: the stroke is " + three_digits(s) + " times the onset of collect-and-collide (" +
                               in_mm(at(opt, {"x_onset_m"})) + "), so the bed is in the scattered state and η* is its empirical fit's.";
  }
  return a;
}

Answer decay_answer(const json& r, const json& c) {
  Answer a;
  const json& d = at(r, {"decay"});
  const json& bare = at(d, {"without_beds"});
  const json& duration = at(c, {"task", "duration_s"});
  std::ostringstream p;
  p << "Released from the case's initial state (envelope " << in_mm(at(d, {"initial_envelope_m"})) << " at '"
    << plain(at(d, {"threshold_point"})) << "'), the structure with its dampers "
    << settling_text(at(d, {"settling_time_s"}), duration) << " to "
    << (number(at(d, {"threshold_fraction"})) ? percent(at(d, {"threshold_fraction"}).get<double>()) : "–")
    << " of it (" << plain(at(r, {"method"})) << ")";
  if (bare.is_object()) {
    p << "; without particles (empty containers) it " << settling_text(at(bare, {"settling_time_s"}), duration);
    if (number(at(d, {"settling_time_s"})) && number(at(bare, {"settling_time_s"})))
      p << ": the particles settle it " << times_faster(at(d, {"settling_time_s"}).get<double>(), at(bare, {"settling_time_s"}).get<double>())
        << " the empty containers";
    else if (!number(at(bare, {"settling_time_s"})))
      p << " (its envelope at the end: " << in_mm(at(bare, {"final_envelope_m"})) << ")";
  }
  p << ".";
  a.paragraphs.push_back(p.str());
  return a;
}

Answer frf_answer(const json& r) {
  Answer a;
  const json& f = at(r, {"frf"});
  const json& peaks = at(f, {"peaks"});
  const json& linear = at(f, {"linear_peaks"});
  if (!peaks.is_array() || peaks.empty()) return a;
  a.paragraphs.push_back("Response " + plain(at(f, {"magnitude"})) + ", with the particles and without them (empty containers):");
  for (const auto& peak : peaks) {
    std::ostringstream p;
    p << "Peak of '" << plain(at(peak, {"output"})) << "': " << plain(at(peak, {"magnitude"})) << " at " << plain(at(peak, {"frequency_hz"}))
      << " Hz, equivalent damping ratio " << plain(at(peak, {"damping_ratio"}));
    // Without particles: the same output's peak nearest in frequency (the same mode).
    const json* nearest = nullptr;
    for (const auto& lin : linear)
      if (at(lin, {"output"}) == at(peak, {"output"}) && number(at(lin, {"magnitude"})) && number(at(lin, {"frequency_hz"})) &&
          number(at(peak, {"frequency_hz"})) &&
          (!nearest || std::abs(at(lin, {"frequency_hz"}).get<double>() - at(peak, {"frequency_hz"}).get<double>()) <
                           std::abs(at(*nearest, {"frequency_hz"}).get<double>() - at(peak, {"frequency_hz"}).get<double>())))
        nearest = &lin;
    if (nearest && number(at(peak, {"magnitude"}))) {
      const double ratio = at(*nearest, {"magnitude"}).get<double>() / at(peak, {"magnitude"}).get<double>();
      p << "; without particles " << plain(at(*nearest, {"magnitude"})) << " at " << plain(at(*nearest, {"frequency_hz"}))
        << " Hz (damping ratio " << plain(at(*nearest, {"damping_ratio"})) << "): the particles lower the peak "
        << three_digits(ratio) << " times (" << three_digits(-20.0 * std::log10(ratio)) << " dB)";
    }
    p << ".";
    a.paragraphs.push_back(p.str());
  }
  if (at(f, {"jumps"}).is_array() && !at(f, {"jumps"}).empty())
    a.paragraphs.push_back("The response jumps at " + std::to_string(at(f, {"jumps"}).size()) +
                           " frequencies, where a bed crosses the onset of collect-and-collide: see the plot.");
  return a;
}

Answer placement_answer(const json& r) {
  Answer a;
  std::ostringstream p;
  const json& gain = at(r, {"improvement_over_current"});
  p << "Put the damper " << plain(at(r, {"design", "position_m"})) << " m along the structure: its objective ("
    << words(at(r, {"objective", "kind"})) << " of the " << plain(at(r, {"objective", "unit"})) << " added to the target modes) is "
    << plain(at(r, {"objective", "value"})) << ", ";
  if (number(gain) && std::abs(gain.get<double>() - 1.0) < 5e-3) p << "the same as at the case's own site";
  else p << plain(gain) << " times that at the case's own site (" << plain(at(r, {"current", "objective"})) << ")";
  p << "; " << plain(at(r, {"sites_evaluated"})) << " positions tried.";
  a.paragraphs.push_back(p.str());
  return a;
}

Answer modes_answer(const json& r) {
  Answer a;
  for (const auto& m : at(r, {"modes"})) {
    std::ostringstream p;
    p << "Mode " << plain(at(m, {"mode"})) << ": " << plain(at(m, {"frequency_hz"})) << " Hz with the empty containers ("
      << plain(at(m, {"bare_frequency_hz"})) << " Hz without them)";
    if (number(at(m, {"backbone", "max_added_damping_ratio"})))
      p << "; the particles add up to ζ = " << plain(at(m, {"backbone", "max_added_damping_ratio"})) << " at a damper amplitude of "
        << in_mm(at(m, {"backbone", "max_added_damping_amplitude_m"}));
    p << ".";
    a.paragraphs.push_back(p.str());
  }
  return a;
}

}  // namespace

Answer report_answer(const json& result, const json& case_resolved) {
  const std::string task = result.is_object() && result.contains("task") && result["task"].is_string() ? result["task"].get<std::string>() : "";
  if (task == "filling_ratios" || at(result, {"designs", "chosen"}).is_object()) return filling_ratios_answer(result, case_resolved);
  if (task == "damper_design") return damper_design_answer(result, case_resolved);
  if (task == "decay") return decay_answer(result, case_resolved);
  if (task == "frf") return frf_answer(result);
  if (task == "placement") return placement_answer(result);
  if (task == "modes") return modes_answer(result);
  return {};
}

}  // namespace pdamp::report
