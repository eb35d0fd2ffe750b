// Filling ratios of a multi-layer damper: relaxed solve, whole-slab designs, baseline.
#include "pdamp/optimizer/filling_ratios.hpp"

#include "pdamp/structure/sampled_decay.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/one_dimensional.hpp"
#include "pdamp/base/run_errors.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "pdamp/optimizer/solve.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace pdamp::optimizer {

namespace {

constexpr double kFitsTolerance = 1e-9;   // as formulas::collected_lattice's "fits"
constexpr double kEmptyLayerSlabs = 1e-9; // below: the layer holds nothing and is left out
constexpr double kWholeTolerance = 1e-6;  // a relaxed n_k this close to a whole number is that number
constexpr int kMaxLayers = 10;
/// The single-compartment reference: clearances scanned, then golden-section steps.
constexpr std::size_t kSingleCompartmentScan = 41;
constexpr int kSingleCompartmentRefinements = 20;

using base::format_number;

double clock_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double total_mass(const FillingRatioOptions& o, std::span<const double> n) {
  double m = 0.0;
  for (std::size_t k = 0; k < n.size(); ++k) m += n[k] * o.layers[k].slab_mass_kg();
  return m;
}

double total_slabs(std::span<const double> n) {
  double s = 0.0;
  for (double v : n) s += v;
  return s;
}

/// Within the budget and slab limit, to a relative 1e-9 (the relaxed optimum sits on it).
bool feasible(const FillingRatioOptions& o, std::span<const double> n) {
  if (o.mass_budget_kg > 0.0 && total_mass(o, n) > o.mass_budget_kg * (1.0 + 1e-9)) return false;
  if (o.max_total_slabs > 0 && total_slabs(n) > o.max_total_slabs + 1e-9) return false;
  return true;
}

}  // namespace

std::string_view to_string(FillingObjective objective) {
  return objective == FillingObjective::kSettlingTime ? "settling_time" : "integral_square";
}

const base::Fields<LayerDesign>& LayerDesign::fields() {
  using L = LayerDesign;
  static const auto f =
      base::Fields<L>()
          .field("name", &L::name, "", "the layer")
          .field("slabs", &L::slabs, "", "n_k, whole for integer designs", base::kNullable)
          .field("particles", &L::particles, "", "spheres")
          .field("filling_ratio", &L::filling_ratio, "1", "n k 2r/L of the settled bed", base::kNullable)
          .field("volume_fraction", &L::volume_fraction, "1", "sphere volume over container volume (0: unknown)")
          .field("clearance_m", &L::clearance_m, "m", "free length above the bed along the drive")
          .field("bed_mass_kg", &L::bed_mass_kg, "kg", "particle mass");
  return f;
}

std::vector<double> FillingDesign::slabs() const {
  std::vector<double> n;
  for (const auto& l : layers) n.push_back(l.slabs);
  return n;
}

const base::Fields<FillingDesign>& FillingDesign::fields() {
  using D = FillingDesign;
  static const auto f =
      base::Fields<D>()
          .field("layers", &D::layers, "", "each layer's bed")
          .derived("slabs", [](const D& d) { return d.slabs(); }, "", "n_k of each layer", base::kHidden)
          .field("total_mass_kg", &D::total_mass_kg, "kg", "particle mass in all layers")
          .field("total_slabs", &D::total_slabs, "", "slabs in all layers", base::kHidden)
          .field("feasible", &D::feasible, "", "within the mass budget and the slab limit")
          .field("settled", &D::settled, "", "the decay settles within the duration")
          .field("settling_time_s", &D::settling_time_s, "s", "time to settle (null: not settled)", base::kNullable)
          .field("integral_square_m2_s", &D::integral_square_m2_s, "m2_s", "1/2 integral of e^2 dt (integral_square only)",
                 base::kNullable)
          .field("objective", &D::objective, "s or m2_s", "the minimised value");
  return f;
}

const base::Fields<FillingDesign>& FillingDesign::neighbour_fields() {
  static const auto f = fields().view({"slabs", "objective", "settling_time_s", "total_mass_kg"});
  return f;
}

int LayerCandidate::max_slabs() const {
  if (!(slab_length_m > 0.0) || !(inner_length_m > 0.0) || spheres_per_lane < 1) return 0;
  const int rows = static_cast<int>(std::floor(inner_length_m / slab_length_m * (1.0 + kFitsTolerance)));
  return (rows - 1) / spheres_per_lane;
}

std::vector<std::string> FillingRatioOptions::validate() const {
  std::vector<std::string> problems;
  if (layers.empty() || static_cast<int>(layers.size()) > kMaxLayers)
    problems.push_back("layers: has " + std::to_string(layers.size()) + " entries: must have 1 to " +
                       std::to_string(kMaxLayers));
  double lightest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < layers.size(); ++k) {
    const auto& l = layers[k];
    const std::string at = "layers[" + std::to_string(k) + "].";
    if (l.name.empty()) problems.push_back(at + "name: must not be empty");
    for (std::size_t j = 0; j < k; ++j)
      if (layers[j].name == l.name) problems.push_back(at + "name = " + l.name + ": must be unique");
    if (!(l.inner_length_m > 0.0 && std::isfinite(l.inner_length_m)))
      problems.push_back(at + "inner_length_m = " + format_number(l.inner_length_m, 10) + ": must be > 0 and finite");
    if (!(l.slab_length_m > 0.0 && std::isfinite(l.slab_length_m)))
      problems.push_back(at + "slab_length_m = " + format_number(l.slab_length_m, 10) + ": must be > 0 and finite");
    else if (l.spheres_per_lane >= 1 && l.max_slabs() < 1)
      problems.push_back(at + "inner_length_m = " + format_number(l.inner_length_m, 10) + ": must hold the " +
                         std::to_string(l.spheres_per_lane) + " settled row(s) of one slab and one row of travel, " +
                         format_number(l.slab_length_m, 10) + " m each");
    if (l.spheres_per_slab < 1)
      problems.push_back(at + "spheres_per_slab = " + std::to_string(l.spheres_per_slab) + ": must be >= 1");
    if (l.spheres_per_lane < 1 || l.spheres_per_lane > std::max(l.spheres_per_slab, 1))
      problems.push_back(at + "spheres_per_lane = " + std::to_string(l.spheres_per_lane) +
                         ": must be in [1, spheres_per_slab]");
    if (!(l.sphere_mass_kg > 0.0 && std::isfinite(l.sphere_mass_kg)))
      problems.push_back(at + "sphere_mass_kg = " + format_number(l.sphere_mass_kg, 10) + ": must be > 0 and finite");
    if (!(l.cross_section_m2 >= 0.0 && std::isfinite(l.cross_section_m2)) ||
        !(l.sphere_volume_m3 >= 0.0 && std::isfinite(l.sphere_volume_m3)))
      problems.push_back(at + "cross_section_m2, sphere_volume_m3: must be >= 0 and finite");
    if (l.initial_slabs < 0 || l.initial_slabs > std::max(l.max_slabs(), 0))
      problems.push_back(at + "initial_slabs = " + std::to_string(l.initial_slabs) + ": must be in [0, " +
                         std::to_string(std::max(l.max_slabs(), 0)) + "]");
    if (l.spheres_per_slab >= 1 && l.sphere_mass_kg > 0.0) lightest = std::min(lightest, l.slab_mass_kg());
  }
  if (!(mass_budget_kg >= 0.0 && std::isfinite(mass_budget_kg)))
    problems.push_back("mass_budget_kg = " + format_number(mass_budget_kg, 10) + ": must be >= 0 and finite");
  else if (mass_budget_kg > 0.0 && std::isfinite(lightest) && mass_budget_kg < lightest * (1.0 - 1e-9))
    problems.push_back("mass_budget_kg = " + format_number(mass_budget_kg, 10) + ": must be >= the lightest slab, " +
                       format_number(lightest, 10) + " kg (no layer could hold a whole slab)");
  if (max_total_slabs < 0) problems.push_back("max_total_slabs = " + std::to_string(max_total_slabs) + ": must be >= 0");
  if (max_enumerated_designs < 0 || max_enumerated_designs > kMaxEnumeratedDesigns)
    problems.push_back("max_enumerated_designs = " + std::to_string(max_enumerated_designs) + ": must be in [0, " +
                       std::to_string(kMaxEnumeratedDesigns) + "]");
  if (mass_budget_kg == 0.0 && max_total_slabs == 0)
    problems.push_back("mass_budget_kg = 0 and max_total_slabs = 0: give at least one constraint");
  if (integral_samples < 10 || integral_samples > 100000)
    problems.push_back("integral_samples = " + std::to_string(integral_samples) + ": must be in [10, 100000]");
  if (!bed_models.empty()) {
    long designs = 1;
    if (bed_models.size() != layers.size())
      problems.push_back("bed_models: " + std::to_string(bed_models.size()) + " layers for " +
                         std::to_string(layers.size()) + " candidates");
    for (std::size_t k = 0; k < std::min(bed_models.size(), layers.size()); ++k) {
      const int max_slabs = std::max(layers[k].max_slabs(), 0);
      designs = std::min(designs * (max_slabs + 1L), kMaxEnumeratedDesigns + 1L);
      bool complete = bed_models[k].size() == static_cast<std::size_t>(max_slabs) + 1;
      for (std::size_t n = 1; complete && n < bed_models[k].size(); ++n) complete = bed_models[k][n] != nullptr;
      if (!complete)
        problems.push_back("bed_models[" + std::to_string(k) + "]: must hold a model for every slab count 1.." +
                           std::to_string(max_slabs));
    }
    if (designs > kMaxEnumeratedDesigns)
      problems.push_back("bed_models: more than " + std::to_string(kMaxEnumeratedDesigns) +
                         " whole-slab designs to enumerate");
  }
  if (!(decay.duration_s > 0.0 && std::isfinite(decay.duration_s)))
    problems.push_back("decay.duration_s = " + format_number(decay.duration_s, 10) + ": must be > 0 and finite");
  return problems;
}

structure::Damper filling_damper(const FillingRatioOptions& options, std::span<const double> slabs) {
  if (slabs.size() != options.layers.size())
    throw std::invalid_argument("filling_damper: " + std::to_string(slabs.size()) + " slab counts for " +
                                std::to_string(options.layers.size()) + " layers");
  structure::Damper damper = options.damper;
  damper.layers.clear();
  for (std::size_t k = 0; k < slabs.size(); ++k) {
    const auto& l = options.layers[k];
    const double n = slabs[k];
    if (!(n >= 0.0 && n <= l.max_slabs()))
      throw std::invalid_argument("filling_damper: layer '" + l.name + "': slabs = " + format_number(n, 10) +
                                  ": must be in [0, " + std::to_string(l.max_slabs()) + "]");
    if (n <= kEmptyLayerSlabs) continue;
    structure::DamperLayer layer;
    layer.name = l.name;
    layer.bed_mass_kg = n * l.slab_mass_kg();
    if (options.bed_models.empty()) {
      formulas::ModelOptions model_options = options.model_options;
      model_options.rows_along_drive = n * l.spheres_per_lane;  // the settled bed's rows (the tail needs 3)
      layer.loss_model = std::make_shared<surrogate::ClosedFormLossModel>(options.model, l.clearance_m(n), model_options);
    } else {
      if (std::abs(n - std::round(n)) > kWholeTolerance)
        throw std::invalid_argument("filling_damper: layer '" + l.name + "': slabs = " + format_number(n, 10) +
                                    ": calibrated beds exist for whole slabs only");
      layer.loss_model = options.bed_models[k][static_cast<std::size_t>(std::lround(n))];
    }
    damper.layers.push_back(std::move(layer));
  }
  return damper;
}

namespace {

/// The free decay of `damper` (with the fixed dampers) scored by the objective: settled,
/// settling time, ½∫e² dt and the objective of `design`.
void score_decay(const structure::ModalModel& model, const FillingRatioOptions& options, structure::Damper damper,
                 FillingDesign& design) {
  std::vector<structure::Damper> dampers = {std::move(damper)};
  dampers.insert(dampers.end(), options.fixed_dampers.begin(), options.fixed_dampers.end());
  structure::FreeDecayOptions decay = options.decay;
  const bool integral = options.objective == FillingObjective::kIntegralSquare;
  decay.sample_times_s = structure::uniform_sample_times(decay.duration_s, integral ? options.integral_samples : 2);
  const auto result = structure::free_decay(model, dampers, decay);

  design.settled = result.outcome == structure::FreeDecay::Outcome::kSettled;
  design.settling_time_s = result.settling_time_s;
  design.integral_square_m2_s = std::numeric_limits<double>::quiet_NaN();
  if (integral) {
    std::vector<double> t, e;
    for (const auto& sample : result.samples) t.push_back(sample.time_s), e.push_back(sample.threshold_measure_m);
    const double sum = structure::half_integral_square(t, e);
    design.integral_square_m2_s = sum;
    design.objective = sum;
  } else if (design.settled) {
    design.objective = result.settling_time_s;
  } else {
    const double end = result.samples.back().threshold_measure_m;
    design.objective = decay.duration_s * (1.0 + std::log(std::max(end / result.threshold_used_m, 1.0)));
  }
}

}  // namespace

FillingDesign evaluate_filling_design(const structure::ModalModel& model, const FillingRatioOptions& options,
                                      std::span<const double> slabs) {
  FillingDesign design;
  for (std::size_t k = 0; k < slabs.size(); ++k) {
    const auto& l = options.layers[k];
    LayerDesign d;
    d.name = l.name;
    d.slabs = slabs[k];
    d.clearance_m = l.clearance_m(slabs[k]);
    d.filling_ratio = 1.0 - d.clearance_m / l.inner_length_m;
    d.bed_mass_kg = slabs[k] * l.slab_mass_kg();
    d.particles = slabs[k] * l.spheres_per_slab;
    d.volume_fraction = l.cross_section_m2 > 0.0
                            ? d.particles * l.sphere_volume_m3 / (l.inner_length_m * l.cross_section_m2)
                            : 0.0;
    design.total_slabs += static_cast<int>(std::lround(slabs[k]));
    design.layers.push_back(std::move(d));
  }
  design.total_mass_kg = total_mass(options, slabs);
  design.feasible = feasible(options, slabs);
  score_decay(model, options, filling_damper(options, slabs), design);
  return design;
}

FillingDesign evaluate_single_compartment(const structure::ModalModel& model, const FillingRatioOptions& options,
                                          double mass_kg, double particles, double clearance_m) {
  FillingDesign design;
  LayerDesign d;
  d.name = kSingleCompartment;
  d.slabs = std::numeric_limits<double>::quiet_NaN();
  d.filling_ratio = std::numeric_limits<double>::quiet_NaN();
  d.clearance_m = clearance_m;
  d.bed_mass_kg = mass_kg;
  d.particles = particles;
  design.layers.push_back(std::move(d));
  design.total_mass_kg = mass_kg;
  design.feasible = options.mass_budget_kg <= 0.0 || mass_kg <= options.mass_budget_kg * (1.0 + 1e-9);
  structure::Damper damper = options.damper;
  damper.layers.clear();
  structure::DamperLayer layer;
  layer.name = kSingleCompartment;
  layer.bed_mass_kg = mass_kg;
  layer.loss_model = std::make_shared<surrogate::ClosedFormLossModel>(options.model, clearance_m, options.model_options);
  damper.layers.push_back(std::move(layer));
  score_decay(model, options, std::move(damper), design);
  return design;
}

namespace {

/// The design's particle mass in one compartment, its clearance chosen for the best
/// objective: a scan of kSingleCompartmentScan clearances, log-spaced from the smallest
/// candidate's sphere diameter (one sphere of travel) to the longest candidate's inner
/// length, then a golden-section search between the best scanned clearance's neighbours
/// (the objective is piecewise smooth in h: the onset's cliff moves with it).
FillingDesign best_single_compartment(const structure::ModalModel& model, const FillingRatioOptions& options,
                                      const FillingDesign& design, int& evaluations) {
  double particles = 0.0;
  for (const auto& l : design.layers) particles += l.particles;
  double h_lo = std::numeric_limits<double>::infinity(), h_hi = 0.0;
  for (const auto& l : options.layers) h_lo = std::min(h_lo, l.slab_length_m), h_hi = std::max(h_hi, l.inner_length_m);
  const auto at = [&](double h) {
    ++evaluations;
    return evaluate_single_compartment(model, options, design.total_mass_kg, particles, h);
  };
  std::vector<double> h(kSingleCompartmentScan);
  FillingDesign best;
  best.objective = std::numeric_limits<double>::infinity();
  std::size_t best_k = 0;
  for (std::size_t k = 0; k < h.size(); ++k) {
    h[k] = h_lo * std::pow(h_hi / h_lo, static_cast<double>(k) / static_cast<double>(h.size() - 1));
    auto d = at(h[k]);
    if (d.objective < best.objective) best = std::move(d), best_k = k;
  }
  // Both inner points are evaluated afresh at every step (two evaluations a step), in ln h.
  base::GoldenSectionOptions search;
  search.max_iterations = kSingleCompartmentRefinements;
  search.min_width = 1e-6;
  search.reuse_inner_point = false;
  base::golden_section(
      [&](double log_h) {
        auto d = at(std::exp(log_h));
        const double objective = d.objective;
        if (objective < best.objective) best = std::move(d);
        return objective;
      },
      std::log(h[best_k == 0 ? 0 : best_k - 1]), std::log(h[std::min(best_k + 1, h.size() - 1)]), search);
  return best;
}

}  // namespace

FillingRatioResult optimize_filling_ratios(const structure::ModalModel& model, const FillingRatioOptions& options,
                                           const Options& solver) {
  if (const auto problems = options.validate(); !problems.empty()) {
    std::string text;
    for (const auto& p : problems) text += (text.empty() ? "" : "\n") + p;
    throw std::invalid_argument(text);
  }
  const double start = clock_s();
  FillingRatioResult out;
  const std::size_t n_layers = options.layers.size();
  auto evaluate = [&](std::span<const double> n) {
    ++out.decay_evaluations;
    return evaluate_filling_design(model, options, n);
  };

  std::vector<double> initial(n_layers);
  for (std::size_t k = 0; k < n_layers; ++k) initial[k] = options.layers[k].initial_slabs;
  out.initial = evaluate(initial);
  if (!out.initial.feasible)
    out.warnings.push_back("the starting design (the case's particle counts) exceeds the budget: the search starts "
                           "inside the bounds instead");

  // Every feasible whole-slab design (an odometer over the layers' counts), the best chosen:
  // calibrated beds exist at whole slabs only, and on the closed forms a small design space
  // is cheaper to enumerate than to trust the rounding across the objective's jumps.
  const auto enumerate_whole_slab_designs = [&] {
    std::vector<double> n(n_layers, 0.0);
    double best = std::numeric_limits<double>::infinity();
    for (;;) {
      ++out.neighbours_total;
      if (feasible(options, n)) {
        out.neighbours.push_back(evaluate(n));
        if (out.neighbours.back().objective < best) best = out.neighbours.back().objective, out.chosen = out.neighbours.back();
      }
      std::size_t k = 0;
      while (k < n_layers && n[k] >= options.layers[k].max_slabs()) n[k++] = 0.0;
      if (k == n_layers) break;
      n[k] += 1.0;
    }
    out.enumerated = true;
    out.neighbours_feasible = static_cast<int>(out.neighbours.size());
  };
  long designs = 1;
  for (const auto& l : options.layers)
    designs = std::min(designs * (std::max(l.max_slabs(), 0) + 1L), FillingRatioOptions::kMaxEnumeratedDesigns + 1L);

  if (!options.bed_models.empty()) {
    enumerate_whole_slab_designs();
    out.relaxed = out.chosen;
    out.summary.outcome = Outcome::kConverged;
    out.summary.evaluations = out.decay_evaluations;
    for (const auto& l : out.chosen.layers) out.summary.x.push_back(l.slabs);
    out.summary.message = "every feasible whole-slab design with the calibrated beds (" +
                          std::to_string(out.neighbours.size()) + " designs)";
  } else {
    // 1. The continuous relaxation: n_k real, mass and clearance linear in n_k.
    Problem problem;
    for (std::size_t k = 0; k < n_layers; ++k) {
      const auto& l = options.layers[k];
      const double upper = l.max_slabs();
      problem.variables.push_back({"slabs_" + l.name, "", 0.0, upper, std::clamp<double>(l.initial_slabs, 0.0, upper)});
    }
    problem.objective = {std::string(to_string(options.objective)),
                         [&](std::span<const double> x) { return evaluate(x).objective; }, nullptr};
    if (options.mass_budget_kg > 0.0) {
      // Scaled to kg/budget so that the constraint tolerance is relative.
      problem.constraints.push_back(
          {"mass_budget_kg",
           [&](std::span<const double> x) { return total_mass(options, x) / options.mass_budget_kg - 1.0; },
           [&](std::span<const double>, std::span<double> g) {
             for (std::size_t k = 0; k < n_layers; ++k) g[k] = options.layers[k].slab_mass_kg() / options.mass_budget_kg;
           }});
    }
    if (options.max_total_slabs > 0) {
      problem.constraints.push_back(
          {"max_total_slabs", [&](std::span<const double> x) { return total_slabs(x) / options.max_total_slabs - 1.0; },
           [&](std::span<const double>, std::span<double> g) {
             for (std::size_t k = 0; k < n_layers; ++k) g[k] = 1.0 / options.max_total_slabs;
           }});
    }
    out.summary = solve(problem, solver);
    out.relaxed = evaluate(out.summary.x);
  }
  if (options.bed_models.empty() && designs <= options.max_enumerated_designs) {
    // 2. Every whole-slab design (the relaxed optimum stays the continuous reference).
    enumerate_whole_slab_designs();
  } else if (options.bed_models.empty()) {
    // 2. Every rounded neighbour of the relaxed optimum (floor/ceil per fractional n_k).
    std::vector<double> base(n_layers);
    std::vector<std::size_t> fractional;
    for (std::size_t k = 0; k < n_layers; ++k) {
      const double x = out.summary.x[k];
      const double whole = std::round(x);
      if (std::abs(x - whole) <= kWholeTolerance) {
        base[k] = whole;
      } else {
        base[k] = std::floor(x);
        fractional.push_back(k);
      }
    }
    out.neighbours_total = 1 << fractional.size();
    double best = std::numeric_limits<double>::infinity();
    for (int mask = 0; mask < out.neighbours_total; ++mask) {
      std::vector<double> n = base;
      for (std::size_t b = 0; b < fractional.size(); ++b)
        if (mask & (1 << b)) n[fractional[b]] += 1.0;
      if (!feasible(options, n)) continue;
      ++out.neighbours_feasible;
      out.neighbours.push_back(evaluate(n));
      if (out.neighbours.back().objective < best) {
        best = out.neighbours.back().objective;
        out.chosen = out.neighbours.back();
      }
    }
    if (out.neighbours.empty()) {
      // Cannot happen for a feasible relaxed point (flooring only lowers mass and slabs).
      throw base::NumericalError("optimize_filling_ratios: no rounded neighbour of the relaxed optimum is feasible (" +
                               out.summary.brief_report() + ")");
    }

  }

  // 3. The single-layer baseline: all mass in one layer, exhaustive over layer and slabs.
  double best_single = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n_layers; ++k) {
    for (int s = 1; s <= options.layers[k].max_slabs(); ++s) {
      std::vector<double> n(n_layers, 0.0);
      n[k] = s;
      if (!feasible(options, n)) break;
      ++out.baseline_evaluations;
      auto d = evaluate(n);
      if (d.objective < best_single) {
        best_single = d.objective;
        out.baseline = std::move(d);
        out.baseline_layer = options.layers[k].name;
      }
    }
  }
  // 4. The references every result states: the structure with its containers empty, and
  // the chosen design's particle mass in one compartment at its own best clearance (what
  // the layering adds beyond the mass).
  out.bare = evaluate(std::vector<double>(n_layers, 0.0));
  out.same_mass = best_single_compartment(model, options, out.chosen, out.decay_evaluations);
  if (out.baseline_evaluations > 0 && out.baseline.objective < out.chosen.objective)
    out.warnings.push_back("the best single-layer design (" + out.baseline_layer + ", objective " +
                           format_number(out.baseline.objective, 10) +
                           ") beats the chosen multi-layer design (objective " +
                           format_number(out.chosen.objective, 10) +
                           "): the relaxed optimum is a local one; raise the global stage's evaluations");
  if (!out.chosen.settled && options.objective == FillingObjective::kSettlingTime)
    out.warnings.push_back("the chosen design does not settle within the duration: lengthen it");
  out.solve_time_s = clock_s() - start;
  return out;
}

}  // namespace pdamp::optimizer
