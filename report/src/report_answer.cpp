// The report's first paragraph: the answer to the question the case asks, in the units a
// damper is built with (g, mm, s), from the typed result and the case.
#include "report_answer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "pdamp/base/number_text.hpp"

namespace pdamp::report {

namespace {

using base::format_number;
namespace opt = optimizer;

bool number(double v) { return std::isfinite(v); }

}  // namespace

std::string three_digits(double value) { return std::isfinite(value) ? format_number(value, 3) : "–"; }
std::string in_mm(double metres) { return number(metres) ? three_digits(metres * 1e3) + " mm" : "–"; }
std::string in_g(double kilograms) { return number(kilograms) ? three_digits(kilograms * 1e3) + " g" : "–"; }

namespace {

std::string in_s(double seconds) { return number(seconds) ? three_digits(seconds) + " s" : "–"; }
/// A name as words: "sub_peak" -> "sub peak".
std::string words(std::string_view name) {
  std::string text(name);
  for (char& ch : text)
    if (ch == '_') ch = ' ';
  return text;
}
std::string percent(double fraction) { return three_digits(100.0 * fraction) + " %"; }

/// The verdict of a failed DEM check: "Do not build on the prediction: a; b. The DEM's
/// numbers above are the better estimate."
std::string do_not_build(const std::vector<std::string>& reasons) {
  std::string text = "Do not build on the prediction: ";
  for (std::size_t i = 0; i < reasons.size(); ++i) text += (i ? "; " : "") + reasons[i];
  return text + ". The DEM's numbers above are the better estimate.";
}

/// "X times faster" of a settling time t against a reference t_ref (both finite).
std::string times_faster(double t, double t_ref) {
  if (!(t > 0.0) || !(t_ref > 0.0)) return "";
  const double ratio = t_ref / t;
  return ratio >= 1.0 ? three_digits(ratio) + " times faster than" : three_digits(1.0 / ratio) + " times slower than";
}

/// One design's layers: "1 slab (16 spheres, 16.4 g) in wide (clearance 60.0 mm)".
std::string layers_text(const opt::FillingDesign& design, bool skip_empty) {
  std::vector<std::string> parts;
  for (const auto& l : design.layers) {
    const double slabs = number(l.slabs) ? l.slabs : 0.0;
    if (skip_empty && slabs == 0.0) continue;
    std::ostringstream part;
    part << three_digits(slabs) << (slabs == 1.0 ? " slab" : " slabs") << " (" << three_digits(l.particles) << " spheres, "
         << in_g(l.bed_mass_kg) << ") in " << l.name << " (clearance " << in_mm(l.clearance_m) << ")";
    parts.push_back(part.str());
  }
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i == 0 ? "" : i + 1 == parts.size() ? " and " : ", ") + parts[i];
  return out.empty() ? "no particles" : out;
}

/// "settles in 9.59 s" or "does not settle within 20.0 s".
std::string settling_text(double time_s, double duration_s) {
  return number(time_s) ? "settles in " + in_s(time_s) : "does not settle within " + in_s(duration_s);
}

const tasks::DesignCheck* check_named(const tasks::Verification& v, std::string_view name) {
  for (const auto& d : v.designs)
    if (d.name == name) return &d;
  return nullptr;
}

/// Which models the filling-ratio prediction came from, in words.
std::string prediction_source(const tasks::FillingRatiosResult& r) {
  if (const auto& cal = r.calibration)
    return "The prediction comes from beds calibrated by the DEM (" + std::to_string(cal->beds.size()) + " beds, " +
           std::to_string(cal->runs) + " run now, the others from the cache): " + std::string(cal->kWhat) + ".";
  return "The prediction comes from the closed forms (each bed's collect-and-collide models), not from the DEM; on a "
         "decay they can miss how a bed comes down from collect-and-collide, so trust it where the DEM check below "
         "passes, or optimise on beds calibrated by the DEM (--method calibrated).";
}

Answer filling_ratios_answer(const tasks::FillingRatiosResult& r, const case_file::Case& c) {
  Answer a;
  const opt::FillingDesign& chosen = r.optimum.chosen;
  const opt::FillingDesign& baseline = r.optimum.baseline;
  const opt::FillingDesign& bare = r.optimum.bare;
  const auto& task = c.task.filling_ratios;
  const double duration = task ? task->decay.duration_s : NAN;
  const bool settling = r.problem.options.objective == opt::FillingObjective::kSettlingTime;
  std::ostringstream p;
  p << "Fill " << layers_text(chosen, true) << ": " << in_g(chosen.total_mass_kg) << " of particles";
  if (number(r.mass_budget_kg)) p << " of the " << in_g(r.mass_budget_kg) << " allowed";
  p << ". ";
  const tasks::Verification* v = r.verification ? &*r.verification : nullptr;
  if (settling) {
    const std::string threshold =
        task && number(task->decay.settling_threshold) ? percent(task->decay.settling_threshold) + " of its initial envelope"
                                                       : "its threshold";
    p << "Released from the case's initial state, the structure is predicted to settle to " << threshold << " in "
      << in_s(chosen.settling_time_s) << "; the best single layer (" << layers_text(baseline, true) << ") "
      << settling_text(baseline.settling_time_s, duration) << " and without particles the structure "
      << settling_text(bare.settling_time_s, duration) << ". ";
    const tasks::DesignCheck* dem_chosen = v ? check_named(*v, "chosen") : nullptr;
    const tasks::DesignCheck* dem_baseline = v ? check_named(*v, "baseline") : nullptr;
    const double chosen_s = dem_chosen ? dem_chosen->dem.settling.settling_time_s : NAN;
    const double baseline_s = dem_baseline ? dem_baseline->dem.settling.settling_time_s : NAN;
    if (number(chosen_s)) {
      p << "The DEM in the loop settles the chosen design in " << in_s(chosen_s);
      if (number(baseline_s))
        p << ", " << times_faster(chosen_s, baseline_s) << " the best single layer (" << in_s(baseline_s) << ")";
      else
        p << "; the best single layer does not settle within " << in_s(v->spec.duration_s);
      p << ". ";
    }
  } else {
    const std::string unit = "m2_s";
    p << "Objective (" << opt::to_string(r.problem.options.objective) << "): " << three_digits(chosen.objective) << " "
      << unit << ", against " << three_digits(baseline.objective) << " for the best single layer and "
      << three_digits(bare.objective) << " without particles. ";
  }
  a.paragraphs.push_back(p.str());
  a.paragraphs.push_back(prediction_source(r));
  if (v) {
    std::ostringstream verdict;
    verdict << "DEM check: " << (v->passed ? "PASS" : "FAIL") << ". ";
    std::vector<std::string> failed;
    for (const char* name : {"chosen", "baseline"}) {
      const tasks::DesignCheck* d = check_named(*v, name);
      if (!d) continue;
      if (!d->passed)
        failed.push_back(std::string("the ") + (std::string(name) == "chosen" ? "chosen design" : "best single layer") +
                         " differs from its prediction by more than " + percent(v->spec.tolerance_relative));
      if (d->softening_check && !d->softening_check->agreement.within)
        failed.push_back(std::string("the ") + name +
                         " design's DEM result changes with stiffer contacts (the softening has not converged)");
    }
    if (!v->ranking_passed) failed.push_back("the DEM does not rank the chosen design ahead of the best single layer");
    if (v->passed) {
      const tasks::DesignCheck* d = check_named(*v, "chosen");
      verdict << "The DEM in the loop agrees with the prediction within the case's " << percent(v->spec.tolerance_relative)
              << ", ranks the chosen design ahead of the best single layer"
              << (d && d->softening_check ? ", and gives the same with stiffer contacts" : "")
              << ": the prediction can be trusted for this design.";
    } else {
      verdict << do_not_build(failed);
    }
    a.verdict = verdict.str();
    a.passed = v->passed;
  } else {
    a.verdict = "Not checked by the DEM (run with the verification to check the prediction).";
  }
  return a;
}

Answer damper_design_answer(const tasks::DamperDesignResult& r, const case_file::Case& c) {
  Answer a;
  const case_file::LayerSpec* layer =
      c.dampers.empty() || c.dampers.front().layers.empty() ? nullptr : &c.dampers.front().layers.front();
  const auto& op = r.operating_point;
  std::ostringstream p;
  p << "A bed of " << (layer ? three_digits(layer->particle_count) : "–") << " " << (layer ? layer->particle_material : "–")
    << " spheres of " << in_mm(layer ? layer->particle_radius_m : NAN) << " radius (" << in_g(r.bed_mass_kg)
    << ") with a clearance of " << in_mm(r.clearance_m) << " along the drive";
  if (r.sizing && number(r.sizing->container_inner_length_along_drive_m))
    p << " (container inner length " << in_mm(r.sizing->container_inner_length_along_drive_m) << ")";
  p << ", shaken at " << three_digits(c.excitation.frequency_hz) << " Hz with a stroke of "
    << in_mm(op ? r.operating_amplitude_m : NAN) << " (intensity Γ = " << three_digits(op ? op->loss.intensity : NAN)
    << "), has a reduced loss factor η* = " << three_digits(op ? op->loss.eta_star : NAN) << ": it dissipates "
    << (op && number(op->e_diss_j) ? three_digits(op->e_diss_j * 1e3) : "–") << " mJ per cycle ("
    << (op ? std::string(formulas::to_string(op->loss.model_used)) : "–") << " collect-and-collide model, state "
    << (op ? words(formulas::to_string(op->loss.regime)) : "–") << "). For this clearance the best stroke is "
    << in_mm(r.optimum.x_opt_m) << " (η* = " << three_digits(r.eta_star_at_design) << ").";
  a.paragraphs.push_back(p.str());
  if (const auto& b = r.buffer) {
    a.paragraphs.push_back("Buffered walls: a " + r.buffer_layer_material + " layer " + in_mm(b->layer_thickness_m) +
                           " thick keeps the strain at " + three_digits(b->allowable_strain) + " in an impact at " +
                           three_digits(b->impact_velocity_m_s) + " m/s (peak force " + three_digits(b->max_force_n) +
                           " N, contact " + (number(b->contact_time_s) ? three_digits(b->contact_time_s * 1e3) : "–") +
                           " ms).");
  }
  if (op && number(op->loss.stroke_over_onset)) {
    const double s = op->loss.stroke_over_onset;
    a.passed = s >= 1.1;
    a.verdict = s >= 1.0 ? "Margin to the cliff: the stroke is " + three_digits(s) + " times the onset of collect-and-collide (" +
                               in_mm(r.optimum.x_onset_m) + ")" +
                               (s < 1.1 ? ", less than 10 % above it: a smaller stroke in service drops η* to the scattered state's." : ".")
                         : "Below the cliff: the stroke is " + three_digits(s) + " times the onset of collect-and-collide (" +
                               in_mm(r.optimum.x_onset_m) + "), so the bed is in the scattered state and η* is its empirical fit's.";
  }
  return a;
}

Answer decay_answer(const tasks::DecayResult& r, const case_file::Case& c) {
  Answer a;
  const tasks::DecaySummary d = tasks::decay_summary(r);
  const tasks::BareDecaySummary bare = tasks::without_beds_summary(r);
  const double duration = c.task.decay ? c.task.decay->duration_s : NAN;
  std::ostringstream p;
  p << "Released from the case's initial state (envelope " << in_mm(d.initial_envelope_m) << " at '" << d.threshold_point
    << "'), the structure with its dampers " << settling_text(d.settling_time_s, duration) << " to "
    << (number(d.threshold_fraction) ? percent(d.threshold_fraction) : "–") << " of it (" << d.method << ")";
  p << "; without particles (empty containers) it " << settling_text(bare.settling_time_s, duration);
  if (number(d.settling_time_s) && number(bare.settling_time_s))
    p << ": the particles settle it " << times_faster(d.settling_time_s, bare.settling_time_s) << " the empty containers";
  else if (!number(bare.settling_time_s))
    p << " (its envelope at the end: " << in_mm(bare.final_envelope_m) << ")";
  p << ".";
  a.paragraphs.push_back(p.str());
  return a;
}

Answer frf_answer(const tasks::FrfResult& r) {
  Answer a;
  const std::vector<tasks::PeakSummary> peaks = tasks::response_peaks(r);
  if (peaks.empty()) return a;
  // Without particles: the harmonic balance's linear peaks (the other methods draw the
  // structure without particles but report no peaks of it).
  const std::vector<tasks::PeakSummary> linear =
      r.harmonic && r.method != tasks::FrfMethod::kCompare
          ? tasks::peak_summaries(r.harmonic->response.linear_peaks, r.harmonic->response.output_names)
          : std::vector<tasks::PeakSummary>{};
  a.paragraphs.push_back("Response " + tasks::magnitude_description(r) +
                         ", with the particles and without them (empty containers):");
  for (const auto& peak : peaks) {
    std::ostringstream p;
    p << "Peak of '" << peak.output << "': " << three_digits(peak.magnitude) << " at " << three_digits(peak.frequency_hz)
      << " Hz, equivalent damping ratio " << three_digits(peak.damping_ratio);
    // Without particles: the same output's peak nearest in frequency (the same mode).
    const tasks::PeakSummary* nearest = nullptr;
    for (const auto& lin : linear)
      if (lin.output == peak.output && number(lin.magnitude) && number(lin.frequency_hz) && number(peak.frequency_hz) &&
          (!nearest || std::abs(lin.frequency_hz - peak.frequency_hz) < std::abs(nearest->frequency_hz - peak.frequency_hz)))
        nearest = &lin;
    if (nearest && number(peak.magnitude)) {
      const double ratio = nearest->magnitude / peak.magnitude;
      p << "; without particles " << three_digits(nearest->magnitude) << " at " << three_digits(nearest->frequency_hz)
        << " Hz (damping ratio " << three_digits(nearest->damping_ratio) << "): the particles lower the peak "
        << three_digits(ratio) << " times (" << three_digits(-20.0 * std::log10(ratio)) << " dB)";
    }
    p << ".";
    a.paragraphs.push_back(p.str());
  }
  if (r.harmonic && r.method != tasks::FrfMethod::kCompare && !r.harmonic->response.branch_ends.empty())
    a.paragraphs.push_back("The response jumps at " + std::to_string(r.harmonic->response.branch_ends.size()) +
                           " frequencies, where a bed crosses the onset of collect-and-collide: see the plot.");
  return a;
}

Answer placement_answer(const tasks::PlacementStudy& study) {
  Answer a;
  const auto& r = study.result;
  const double gain = r.current && r.current->objective > 0.0 ? r.best.objective / r.current->objective : NAN;
  std::ostringstream p;
  p << "Put the damper " << three_digits(r.best.position_m) << " m along the structure: its objective ("
    << words(opt::to_string(study.objective)) << " of the damping ratio added to the target modes) is "
    << three_digits(r.best.objective) << ", ";
  if (number(gain) && std::abs(gain - 1.0) < 5e-3) p << "the same as at the case's own site";
  else p << three_digits(gain) << " times that at the case's own site (" << three_digits(r.current ? r.current->objective : NAN) << ")";
  p << "; " << three_digits(static_cast<double>(r.scan.size())) << " positions tried.";
  a.paragraphs.push_back(p.str());
  a.paragraphs.push_back(std::string("The damping ratios come from ") +
                         (study.method == case_file::LossMethod::kField
                              ? "each layer's effective field"
                              : "the closed forms (each layer's collect-and-collide models)") +
                         ", at the stroke each target mode gives the site, one mode at a time.");
  const auto& v = study.verification;
  if (!v || v->sites.size() < 2) {
    a.verdict = "Not checked by the DEM in the loop (run with the verification to check the prediction).";
    return a;
  }
  const tasks::PlacementSiteCheck& chosen = v->sites.front();
  const tasks::PlacementSiteCheck& other = v->sites.back();
  std::ostringstream verdict;
  verdict << "DEM check: " << (v->passed ? "PASS" : "FAIL") << ". Each target mode decays alone from its stated "
          << "amplitude; over its decay the beds add " << percent(chosen.predicted_objective) << " (the objective) at the "
          << "chosen site by the " << (study.method == case_file::LossMethod::kField ? "fields" : "closed forms")
          << " and " << percent(chosen.dem_objective) << " by the DEM in the loop; at "
          << three_digits(other.predicted.position_m) << " m " << percent(other.predicted_objective) << " and "
          << percent(other.dem_objective) << ". ";
  if (v->passed)
    verdict << "The DEM agrees with the prediction within the case's " << percent(v->settings.tolerance_relative)
            << " and ranks the chosen site first: the prediction can be trusted for this placement.";
  else {
    std::vector<std::string> failed;
    if (!v->chosen_agrees)
      failed.push_back("at the chosen site the damping differs from the DEM's by more than " +
                       percent(v->settings.tolerance_relative) +
                       (v->ranking_agrees ? " (the DEM still ranks the chosen site first)" : ""));
    if (!v->ranking_agrees) failed.push_back("the DEM does not rank the chosen site first");
    verdict << do_not_build(failed);
  }
  a.verdict = verdict.str();
  a.passed = v->passed;
  return a;
}

Answer clearance_answer(const tasks::ClearanceStudy& study) {
  Answer a;
  const auto& r = study.sizing.response;
  std::ostringstream p;
  p << "Make the clearance " << in_mm(r.clearance_m) << ": under a base motion of " << in_mm(study.base_amplitude_m)
    << " the resonant peak of the damper's site is |X/U| = " << three_digits(r.peak_transmissibility) << " at "
    << three_digits(r.peak_frequency_hz) << " Hz, with the damper at X = " << in_mm(r.damper_amplitude_m)
    << (r.held_at_onset ? " (held at the onset of collect-and-collide)" : "") << ". The case's own clearance, "
    << in_mm(study.current.clearance_m) << ", gives " << three_digits(study.current.peak_transmissibility) << ".";
  a.paragraphs.push_back(p.str());
  a.paragraphs.push_back("The peaks come from the harmonic balance of every kept mode with the layer's closed form "
                         "(its collect-and-collide model at each clearance tried); the single-mode closed form gives " +
                         in_mm(study.sizing.estimate.clearance_m) + ".");
  const auto& v = study.verification;
  if (!v) {
    a.verdict = "Not checked by the DEM (run with the verification to check the prediction).";
    return a;
  }
  const tasks::ClearanceCheck& chosen = v->checks.front();
  std::ostringstream verdict;
  verdict << "DEM check: " << (v->passed ? "PASS" : "FAIL") << ". At the chosen clearance the DEM stepped sine peaks at "
          << three_digits(chosen.dem_peak) << " (predicted " << three_digits(chosen.predicted_sweep_peak) << ", "
          << percent(chosen.peak_relative_difference) << "; band centre " << percent(chosen.band_centre_relative_difference)
          << "); at";
  for (std::size_t i = 1; i < v->checks.size(); ++i)
    verdict << (i > 1 ? "," : "") << " " << in_mm(v->checks[i].clearance_m) << " it peaks at "
            << three_digits(v->checks[i].dem_peak) << " (" << words(tasks::to_string(v->checks[i].ranking)) << ")";
  verdict << ". ";
  for (std::size_t i = 1; i < v->checks.size(); ++i)
    if (v->checks[i].predicted_peak > v->checks[i].predicted_sweep_peak * 1.001)
      verdict << "At " << in_mm(v->checks[i].clearance_m) << " the prediction's worst case, "
              << three_digits(v->checks[i].predicted_peak) << " at " << three_digits(v->checks[i].predicted_frequency_hz)
              << " Hz, lies on an upper branch that a sweep from the band's ends does not reach (predicted "
              << three_digits(v->checks[i].predicted_sweep_peak)
              << " for the sweeps); the DEM's stepped sines do not test it. ";
  for (std::size_t i = 1; i < v->checks.size(); ++i)
    if (std::abs(v->checks[i].peak_relative_difference) > v->settings.tolerance_relative)
      verdict << "At " << in_mm(v->checks[i].clearance_m) << " the prediction for a sweep, "
              << three_digits(v->checks[i].predicted_sweep_peak) << ", misses the DEM's "
              << three_digits(v->checks[i].dem_peak) << ": the closed forms do not hold there. ";
  if (v->passed && v->ranking_resolved)
    verdict << "The DEM in the loop agrees with the prediction within the case's " << percent(v->settings.tolerance_relative)
            << " and ranks the chosen clearance lowest: the prediction can be trusted for this design.";
  else if (v->passed)
    verdict << "The DEM in the loop agrees with the prediction at the chosen clearance within the case's "
            << percent(v->settings.tolerance_relative)
            << " and ranks no neighbour below it, but cannot tell every neighbour from it (within twice the standard "
               "errors): the ranking there is the prediction's alone.";
  else {
    std::vector<std::string> failed;
    if (!v->chosen_agrees)
      failed.push_back("the chosen clearance's peak differs from the DEM's by more than " +
                       percent(v->settings.tolerance_relative));
    if (!v->ranking_agrees) failed.push_back("the DEM puts a neighbour's peak below the chosen clearance's");
    verdict << do_not_build(failed);
  }
  a.verdict = verdict.str();
  a.passed = v->passed;
  return a;
}

Answer modes_answer(const tasks::ModesResult& r) {
  Answer a;
  for (Eigen::Index j = 0; j < r.mode_count; ++j) {
    std::ostringstream p;
    p << "Mode " << three_digits(static_cast<double>(j + 1)) << ": " << three_digits(r.frequencies_with_containers_hz[j])
      << " Hz with the empty containers (" << three_digits(r.modal.natural_frequencies_hz[j]) << " Hz without them)";
    if (const auto backbone = tasks::backbone_summary(r, j); backbone && number(backbone->max_added_damping_ratio))
      p << "; the particles add up to ζ = " << three_digits(backbone->max_added_damping_ratio)
        << " at a damper amplitude of " << in_mm(backbone->max_added_damping_amplitude_m)
        << (r.calibration_of(j) != nullptr ? " (the DEM-calibrated bed)" : " (" + std::string(case_file::to_string(r.method)) + ")");
    p << ".";
    a.paragraphs.push_back(p.str());
  }
  std::ostringstream verdict;
  if (!r.dem_checks.empty()) {
    std::vector<std::string> missed;
    for (std::size_t k = 0; k < r.dem_checks.size(); ++k) {
      const auto& check = r.dem_checks[k];
      if (!r.dem_check_passed(k))
        missed.push_back("mode " + std::to_string(check.mode + 1) + " from " + in_mm(check.damper_amplitude_m) + " (" +
                         percent(check.whole_relative_difference()) + ")");
    }
    verdict << "The DEM in the loop decayed " << r.dem_checks.size() << " modes and strokes; ";
    if (missed.empty()) {
      verdict << "each mode's damping ratio by the prediction lies within the case's " << percent(r.dem_check_tolerance)
              << " of the DEM's: the damping against amplitude can be trusted at the strokes checked. ";
    } else {
      verdict << "the prediction misses the DEM's damping ratio by more than the case's " << percent(r.dem_check_tolerance)
              << " at ";
      for (std::size_t k = 0; k < missed.size(); ++k) verdict << (k == 0 ? "" : ", ") << missed[k];
      verdict << ": there the damping ratio is the DEM's"
              << (r.calibrations.empty() ? "; a calibration of the task's modes takes the bed from the DEM. " : ". ");
    }
    a.passed = missed.empty();
  }
  if (const auto& search = r.clearance_search) {
    const auto& s = search->settings;
    const auto& chosen = search->candidates[search->chosen];
    std::ostringstream p;
    const bool lined = !s.wall_layer_thicknesses_m.empty();
    const auto not_built = std::count_if(search->candidates.begin(), search->candidates.end(),
                                         [](const auto& k) { return !k.buildable; });
    p << "Clearance for mode " << s.mode + 1 << ": of " << s.clearances_m.size() << " clearances from "
      << in_mm(s.clearances_m.front()) << " to " << in_mm(s.clearances_m.back());
    if (lined)
      p << ", each with buffered walls lined " << in_mm(s.wall_layer_thicknesses_m.front()) << " to "
        << in_mm(s.wall_layer_thicknesses_m.back()) << " thick (" << s.wall_layer_thicknesses_m.size() << " linings)";
    p << ", each with its bed calibrated from DEM steady states, " << in_mm(chosen.clearance_m)
      << (lined ? " with a " + in_mm(chosen.wall_layer_thickness_m) + " lining" : std::string()) << " (inner length "
      << in_mm(chosen.inner_length_m) << ") adds the most damping over strokes of " << in_mm(s.min_amplitude_m) << " to "
      << in_mm(s.max_amplitude_m) << ": ζ_add = " << three_digits(chosen.objective)
      << (s.objective == case_file::ModesClearanceSearch::Objective::kWorst ? " at the worst stroke." : " on average.");
    if (not_built > 0)
      p << " " << not_built << " candidate" << (not_built == 1 ? " was" : "s were")
        << " not run: the buffer's design impact strains their lining beyond its allowable strain.";
    a.paragraphs.push_back(p.str());
    if (search->verified) {
      verdict << "The DEM decays of mode " << s.mode + 1 << " give ζ_add " << three_digits(chosen.dem_check_mean)
              << " on average at the chosen clearance (calibrated " << three_digits(chosen.predicted_check_mean) << ")";
      for (const auto& candidate : search->candidates)
        if (!candidate.checks.empty() && &candidate != &chosen)
          verdict << ", " << three_digits(candidate.dem_check_mean) << " at " << in_mm(candidate.clearance_m)
                  << (lined ? " lined " + in_mm(candidate.wall_layer_thickness_m) : std::string());
      if (search->passed) {
        verdict << ": the DEM confirms the choice within the case's " << percent(s.verify->tolerance_relative) << ".";
      } else {
        std::vector<std::string> failed;
        if (!search->chosen_agrees)
          failed.push_back("a decay at the chosen clearance misses the DEM by more than " +
                           percent(s.verify->tolerance_relative));
        if (!search->ranking_agrees) failed.push_back("the DEM damps a neighbouring candidate more");
        verdict << ". " << do_not_build(failed);
      }
      a.passed = a.passed.value_or(true) && search->passed;
    }
  }
  a.verdict = verdict.str();
  if (!a.verdict.empty() && a.verdict.back() == ' ') a.verdict.pop_back();
  return a;
}

}  // namespace

Answer report_answer(const TaskResult& result, const case_file::Case& c) {
  struct Visit {
    const case_file::Case& c;
    Answer operator()(std::monostate) const { return {}; }
    Answer operator()(const tasks::FillingRatiosResult* r) const { return filling_ratios_answer(*r, c); }
    Answer operator()(const tasks::DamperDesignResult* r) const { return damper_design_answer(*r, c); }
    Answer operator()(const tasks::DecayResult* r) const { return decay_answer(*r, c); }
    Answer operator()(const tasks::FrfResult* r) const { return frf_answer(*r); }
    Answer operator()(const tasks::PlacementStudy* r) const { return placement_answer(*r); }
    Answer operator()(const tasks::ClearanceStudy* r) const { return clearance_answer(*r); }
    Answer operator()(const tasks::ModesResult* r) const { return modes_answer(*r); }
  };
  return std::visit(Visit{c}, result);
}

}  // namespace pdamp::report
