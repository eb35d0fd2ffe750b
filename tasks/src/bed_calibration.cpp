// Calibrated beds (bed_calibration.hpp).
#include "pdamp/tasks/bed_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>

#include <unistd.h>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/output_file.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/structure/sampled_decay.hpp"
#include "pdamp/surrogate/dem_evaluator.hpp"
#include "pdamp/tasks/decay.hpp"
#include "structure_support.hpp"

namespace pdamp::tasks {

namespace st = structure;
using case_file::Case;
using nlohmann::json;

namespace {

constexpr const char* kCacheFormat = "pdamp.bed_calibration";
/// Raised whenever what a cache file holds or how it is computed from the DEM changes
/// (structure::bed_response_per_period, surrogate::decay_field): it is part of every key.
constexpr int kCacheFormatVersion = 4;  // 3: the bed's force the mean over each sample interval, centred; 4: a digest

json period_rows(const std::vector<surrogate::DecayPeriodResponse>& periods) {
  json rows = json::array();
  for (const auto& p : periods)
    rows.push_back({p.time_s, p.frequency_hz, p.stroke_m, p.eta_star, p.apparent_mass_fraction});
  return rows;
}

/// The digest of a cache document: a hash of everything in it but the digest itself (and
/// the "cached" flag the processes of a distributed run add), so that an edited file (an η*
/// multiplied by 50) is not trusted.
std::string document_digest(json d) {
  d.erase("digest");
  d.erase("cached");
  return surrogate::case_hash(d);
}

json cache_document(const CalibratedBed& bed) {
  json d = {{"format", kCacheFormat},          {"format_version", kCacheFormatVersion},
            {"key", bed.key},                  {"layer", bed.layer},
            {"slabs", bed.slabs},              {"extra_damping_ratio", bed.extra_damping_ratio},
            {"steps", bed.steps},
            {"energy_error", bed.energy_error}, {"wall_time_s", bed.wall_time_s},
            {"periods", period_rows(bed.periods)}, {"field", surrogate::to_json(bed.field)}};
  d["digest"] = document_digest(d);
  return d;
}

/// What a bed is for, which its document must say of itself.
struct BedIdentity {
  double bed_mass_kg = 0.0;  ///< slabs · the layer's slab mass
  double clearance_m = 0.0;  ///< the layer's settled clearance at those slabs
  double duration_s = 0.0;   ///< the calibration's decay
};

BedIdentity identity_of(const case_file::FillingRatioProblem& p, const case_file::CalibrationSpec& spec,
                        const CalibratedBed& bed) {
  const auto& layer = p.options.layers.at(static_cast<std::size_t>(bed.layer_index));
  return {bed.slabs * layer.slab_mass_kg(), layer.clearance_m(bed.slabs), spec.duration_s};
}

/// "" when the document is this bed's (layer, slabs, extra damping, key, digest, bed mass,
/// clearance) and every number in it is in its range, else the first rule broken.
std::string document_problem(const json& d, const CalibratedBed& bed, const BedIdentity& id) {
  const auto same = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)); };
  if (d.at("format") != kCacheFormat || d.at("format_version") != kCacheFormatVersion || d.at("key") != bed.key)
    return "it holds another calibration";
  if (!d.contains("digest") || d.at("digest") != document_digest(d)) return "its content does not match its digest";
  if (d.at("layer") != bed.layer || d.at("slabs") != bed.slabs ||
      !same(d.at("extra_damping_ratio").get<double>(), bed.extra_damping_ratio))
    return "it is the calibration of another bed";
  const json& field = d.at("field");
  if (!same(field.at("bed_mass_kg").get<double>(), id.bed_mass_kg) ||
      !same(field.at("clearance_m").get<double>(), id.clearance_m))
    return "its bed mass or clearance is not this bed's";
  if (d.at("steps").get<std::int64_t>() < 0) return "steps < 0";
  const double energy_error = d.at("energy_error").get<double>(), wall = d.at("wall_time_s").get<double>();
  if (!(energy_error >= 0.0 && energy_error <= 1.0)) return "energy_error outside [0, 1]";
  if (!(wall >= 0.0 && std::isfinite(wall))) return "wall_time_s not >= 0 and finite";
  for (const auto& row : d.at("periods")) {
    const double t = row.at(0).get<double>(), f = row.at(1).get<double>(), x = row.at(2).get<double>();
    // The periods of a decay of duration_s at the case's frequencies (<= 1e4 Hz) and strokes
    // (the clearance's range, <= 100 m); η* and m_app/m_bed in the fields' ranges.
    if (!(t >= 0.0 && t <= id.duration_s * (1.0 + 1e-9)) || !(f > 0.0 && f <= 1e4) || !(x > 0.0 && x <= 100.0))
      return "a period row outside [0, duration] s, (0, 1e4] Hz, (0, 100] m";
    if (const std::string problem = surrogate::field_value_problem(row.at(3).get<double>(), row.at(4).get<double>());
        !problem.empty())
      return "a period row's " + problem;
  }
  return "";
}

/// The bed from a cache document, or false (with the reason in `why`) when it is not this
/// bed's (document_problem).
bool bed_from_document(const json& d, CalibratedBed& bed, const BedIdentity& id, std::string& why) {
  try {
    if (why = document_problem(d, bed, id); !why.empty()) return false;
    bed.field = surrogate::effective_field_from_json(d.at("field"), bed.file.string());
    bed.periods.clear();
    for (const auto& row : d.at("periods"))
      bed.periods.push_back({row.at(0).get<double>(), row.at(1).get<double>(), row.at(2).get<double>(),
                             row.at(3).get<double>(), row.at(4).get<double>()});
    bed.steps = d.at("steps").get<std::int64_t>();
    bed.energy_error = d.at("energy_error").get<double>();
    bed.wall_time_s = d.at("wall_time_s").get<double>();
    return true;
  } catch (const std::exception& e) {
    why = e.what();
    return false;
  }
}

/// The cached bed, or false (with the reason in `why`) when the file is absent, unreadable
/// or of another key.
bool read_cached(CalibratedBed& bed, const BedIdentity& id, std::string& why) {
  if (!std::filesystem::exists(bed.file)) return false;
  try {
    const json d = base::parse_json_document(base::read_input_file(bed.file.string()), bed.file.string());
    return bed.cached = bed_from_document(d, bed, id, why);
  } catch (const std::exception& e) {
    why = e.what();
    return false;
  }
}

/// Runs bed's DEM decay, builds its field and writes its cache file.
json calibrate_bed(const Case& c, const case_file::FillingRatioProblem& p, const case_file::CalibrationSpec& spec,
                   CalibratedBed bed, base::RunHooks& hooks) {
  std::vector<long> slabs(p.options.layers.size(), 0);
  slabs[static_cast<std::size_t>(bed.layer_index)] = bed.slabs;
  const Case design = case_file::with_design(c, slabs, spec.stiffness_softening, true);
  detail::DesignModes modes = detail::design_modes(c, p, slabs);
  modes.modal.damping_ratios.array() += bed.extra_damping_ratio;
  std::vector<st::Damper> containers = {p.options.damper};
  containers.insert(containers.end(), p.options.fixed_dampers.begin(), p.options.fixed_dampers.end());
  case_file::DecayTask decay = c.task.filling_ratios->decay;
  decay.duration_s = spec.duration_s;
  const DemDecay d = dem_decay(design, modes.modal, containers, detail::dem_dampers(design),
                               modes.initial_modal_displacements, decay,
                               "pdamp optimize: calibration (" + bed.layer + ", " + std::to_string(bed.slabs) + " slabs)",
                               "/task/calibration/duration_s", DemDecayCheckpoint{}, hooks);
  const auto& r = d.cosimulation;
  const auto& layer = p.options.layers[static_cast<std::size_t>(bed.layer_index)];
  const double bed_mass_kg = bed.slabs * layer.slab_mass_kg();
  bed.periods = st::bed_response_per_period(r.history.time_s, r.history.site_displacement_m.col(0), d.static_offset_m,
                                            -r.history.container_load_n.col(0), bed_mass_kg);
  try {
    bed.field = surrogate::decay_field(bed.periods, layer.clearance_m(bed.slabs), bed_mass_kg,
                                       surrogate::make_provenance(surrogate::FieldSource::kDem,
                                                                  case_file::physics_hash(design, "dem"),
                                                                  surrogate::dem_model_version()),
                                       spec.strokes_per_decade);
  } catch (const std::invalid_argument& e) {
    throw base::NumericalError("pdamp optimize: the calibration of " + bed.layer + " with " +
                                      std::to_string(bed.slabs) + " slabs gives no field: " + e.what() +
                                      " (/task/calibration/duration_s)");
  }
  bed.steps = r.steps;
  bed.energy_error = r.energy.relative_error;
  bed.wall_time_s = r.wall_time_s;
  const json document = cache_document(bed);
  base::write_file_atomically(bed.file, document.dump(1));
  return document;
}

}  // namespace

std::string calibration_key(const Case& design, const case_file::CalibrationSpec& spec, double extra_damping_ratio) {
  const json& r = design.resolved;
  // The dampers' and layers' names label the bed; they are no part of what it does.
  json dampers = r.value("dampers", json());
  for (auto& damper : dampers) {
    if (!damper.is_object()) continue;
    damper.erase("name");
    if (damper.contains("layers"))
      for (auto& layer : damper["layers"])
        if (layer.is_object()) layer.erase("name");
  }
  json identity = {{"structure", r.value("structure", json())},   {"dampers", dampers},
                   {"materials", r.value("materials", json())},   {"dem", r.value("dem", json())},
                   {"initial_state", r.at("task").value("initial_state", json())},
                   {"duration_s", spec.duration_s},              {"strokes_per_decade", spec.strokes_per_decade},
                   {"dem_model_version", surrogate::dem_model_version()},
                   {"calibration_version", kCacheFormatVersion},
                   {"extra_damping_ratio", extra_damping_ratio}};
  return surrogate::case_hash(identity);
}

std::filesystem::path calibration_cache_file(const std::filesystem::path& cache_dir, const std::string& layer, int slabs,
                                             const std::string& key) {
  // The layer's name only as a safe label: a case's name must not steer the path (the key
  // makes the file unique).
  return cache_dir / (base::safe_file_name(layer) + "_" + std::to_string(slabs) + "_" + key + ".json");
}

std::string prepare_calibration_cache(const std::filesystem::path& cache_dir) {
  if (cache_dir.empty()) return "must name a folder";
  std::error_code error;
  if (std::filesystem::exists(cache_dir, error) && !std::filesystem::is_directory(cache_dir, error))
    return "'" + base::printable(cache_dir.string()) + "' exists and is not a folder";
  std::filesystem::create_directories(cache_dir, error);
  if (error) return "cannot create '" + base::printable(cache_dir.string()) + "': " + error.message();
  // The beds are written atomically beside their final name: try one such file now.
  const auto probe = cache_dir / (".pdamp-write-probe-" + std::to_string(::getpid()));
  bool written = false;
  {
    std::ofstream out(probe);
    written = static_cast<bool>(out << "probe") && static_cast<bool>(out.flush());
  }
  std::filesystem::remove(probe, error);
  if (!written) return "'" + base::printable(cache_dir.string()) + "' is not writable";
  return "";
}

std::filesystem::path default_calibration_cache() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0')
    return std::filesystem::path(xdg) / "pdamp" / "bed_calibration";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0')
    return std::filesystem::path(home) / ".cache" / "pdamp" / "bed_calibration";
  return std::filesystem::path(".pdamp-cache") / "bed_calibration";
}

std::vector<std::vector<std::shared_ptr<const surrogate::LossModel>>> BedCalibration::models() const {
  std::vector<std::vector<std::shared_ptr<const surrogate::LossModel>>> out;
  for (const auto& bed : beds) {
    const auto k = static_cast<std::size_t>(bed.layer_index);
    if (out.size() <= k) out.resize(k + 1);
    if (out[k].size() <= static_cast<std::size_t>(bed.slabs)) out[k].resize(static_cast<std::size_t>(bed.slabs) + 1);
    out[k][static_cast<std::size_t>(bed.slabs)] = std::make_shared<surrogate::EffectiveFieldLossModel>(bed.field);
  }
  return out;
}

namespace {

/// What identifies bed's calibration run beyond its place in the list: its layer, slabs,
/// extra damping and key (the physics); a process asked for it checks that it set up the same.
std::string bed_inputs(const CalibratedBed& bed) {
  return bed.layer + " " + std::to_string(bed.slabs) + " slabs, extra damping " +
         base::format_number(bed.extra_damping_ratio, 17) + ", key " + bed.key;
}

/// Reads or runs `beds` (their key and file set here): cached ones from the cache, the others
/// as one batch of jobs of `executor` (job b: bed b). Every process gets every bed as the
/// primary has it: the processes that served the batch get each bed's document, cached or
/// run, so their beds are the primary's whatever their own cache holds. Returns how many ran.
int read_or_run(const Case& c, const case_file::FillingRatioProblem& p, const case_file::CalibrationSpec& spec,
                const std::filesystem::path& cache_dir, std::vector<CalibratedBed>& beds, base::RunHooks& hooks,
                base::Executor& executor) {
  if (const std::string problem = prepare_calibration_cache(cache_dir); !problem.empty())
    throw base::InputError(cache_dir.string(), "", "the calibration cache " + problem);
  std::vector<std::size_t> to_run;
  for (std::size_t b = 0; b < beds.size(); ++b) {
    CalibratedBed& bed = beds[b];
    std::vector<long> slabs(p.options.layers.size(), 0);
    slabs[static_cast<std::size_t>(bed.layer_index)] = bed.slabs;
    bed.key = calibration_key(case_file::with_design(c, slabs, spec.stiffness_softening, true), spec,
                              bed.extra_damping_ratio);
    bed.file = calibration_cache_file(cache_dir, bed.layer, bed.slabs, bed.key);
    std::string why;
    if (!read_cached(bed, identity_of(p, spec, bed), why)) {
      if (!why.empty()) hooks.note("pdamp: warning: " + bed.file.string() + " is not used (" + why + "): it runs again");
      to_run.push_back(b);
    }
  }
  base::Jobs<json> jobs(
      executor, [&](std::size_t b) { return calibrate_bed(c, p, spec, beds.at(b), hooks); },
      [&](std::size_t b) { return bed_inputs(beds.at(b)); });
  auto shared = jobs.shared_results();  // every bed's document, as the primary has it
  if (!shared) {
    std::vector<json> ran(to_run.size());
    base::for_each_concurrently(
        to_run.size(), base::parallel_jobs(executor, to_run.size()), [&](std::size_t j) { ran[j] = jobs(to_run[j]); },
        static_cast<std::size_t>(std::max(executor.concurrency(2), 1)));
    for (std::size_t j = 0; j < to_run.size(); ++j) {
      CalibratedBed& bed = beds[to_run[j]];
      std::string why;
      // What the job returned is what it wrote to the cache (on this process or another).
      if (!bed_from_document(ran[j], bed, identity_of(p, spec, bed), why))
        throw base::NumericalError("pdamp optimize: the calibration of " + bed.layer + " with " +
                                   std::to_string(bed.slabs) + " slabs came back unreadable (" + why + ")");
    }
    std::vector<json> documents;
    for (const auto& bed : beds) documents.push_back(cache_document(bed));
    for (std::size_t b = 0; b < beds.size(); ++b) documents[b]["cached"] = beds[b].cached;
    jobs.end(documents);
    return static_cast<int>(to_run.size());
  }
  if (shared->size() != beds.size())
    throw std::runtime_error("the primary process calibrated " + std::to_string(shared->size()) + " beds, this one " +
                             std::to_string(beds.size()) + ": the processes differ");
  int runs = 0;
  for (std::size_t b = 0; b < beds.size(); ++b) {
    CalibratedBed& bed = beds[b];
    std::string why;
    if (!bed_from_document((*shared)[b], bed, identity_of(p, spec, bed), why))
      throw std::runtime_error("the primary process's calibration of " + bed.layer + " with " +
                               std::to_string(bed.slabs) + " slabs is not this process's (" + why + ")");
    bed.cached = (*shared)[b].at("cached").get<bool>();
    runs += bed.cached ? 0 : 1;
  }
  return runs;
}

}  // namespace

BedCalibration calibrate_beds(const Case& c, const case_file::FillingRatioProblem& p,
                              const case_file::CalibrationSpec& spec, const std::filesystem::path& cache_dir,
                              base::RunHooks& hooks, base::Executor& executor) {
  const auto start = std::chrono::steady_clock::now();
  BedCalibration out;
  out.spec = spec;
  out.cache_dir = cache_dir;
  for (std::size_t k = 0; k < p.options.layers.size(); ++k) {
    for (int n = 1; n <= p.options.layers[k].max_slabs(); ++n) {
      CalibratedBed bed;
      bed.layer = p.options.layers[k].name;
      bed.layer_index = static_cast<int>(k);
      bed.slabs = n;
      out.beds.push_back(std::move(bed));
    }
  }
  out.runs = read_or_run(c, p, spec, cache_dir, out.beds, hooks, executor);
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

double decay_damping_ratio(std::span<const double> time_s, std::span<const double> envelope_m, double frequency_hz) {
  if (time_s.size() < 2 || envelope_m.size() != time_s.size() || !(frequency_hz > 0.0)) return NAN;
  const double duration = time_s.back() - time_s.front();
  const double ratio = envelope_m.front() / envelope_m.back();
  if (!(duration > 0.0) || !(ratio > 0.0) || !std::isfinite(ratio)) return NAN;
  return std::log(ratio) / (2.0 * std::numbers::pi * frequency_hz * duration);
}

std::vector<std::string> recalibrate_in_design(const Case& c, const case_file::FillingRatioProblem& p,
                                               BedCalibration& calibration, const std::vector<long>& slabs,
                                               double design_damping_ratio, double design_threshold_m, base::RunHooks& hooks,
                                               base::Executor& executor) {
  const auto start = std::chrono::steady_clock::now();
  // A design of one bed is that bed alone: its calibration already came down at its rate.
  if (std::count_if(slabs.begin(), slabs.end(), [](long n) { return n > 0; }) < 2) return {};
  // A verification decay too short to give a rate (fewer than two envelope points) says
  // nothing about what the other beds add: the beds keep their calibration (a NaN damping
  // ratio would otherwise reach the recalibration runs' modal model).
  if (!std::isfinite(design_damping_ratio)) return {};
  std::vector<CalibratedBed> beds;
  std::vector<std::size_t> index;  // into calibration.beds
  for (std::size_t b = 0; b < calibration.beds.size(); ++b) {
    const CalibratedBed& alone = calibration.beds[b];
    if (slabs.at(static_cast<std::size_t>(alone.layer_index)) != alone.slabs) continue;
    // The bed's own decay over the same span as the design's: down to the design's threshold.
    std::vector<double> time, stroke;
    for (const auto& period : alone.periods) {
      time.push_back(period.time_s), stroke.push_back(period.stroke_m);
      if (period.stroke_m < design_threshold_m) break;
    }
    const double frequency = alone.periods.empty() ? NAN : alone.periods.front().frequency_hz;
    // What the design's other beds add: the design's average rate of decay less the bed's own
    // (each includes the structure's damping). A bed recalibrated before holds a decay with
    // its extra damping in it: its own alone is that less the extra (damping ratios add).
    const double own = decay_damping_ratio(time, stroke, frequency) - alone.extra_damping_ratio;
    CalibratedBed bed;
    bed.layer = alone.layer;
    bed.layer_index = alone.layer_index;
    bed.slabs = alone.slabs;
    bed.extra_damping_ratio = std::isfinite(own) ? std::max(design_damping_ratio - own, 0.0) : 0.0;
    if (bed.extra_damping_ratio == alone.extra_damping_ratio) continue;
    beds.push_back(std::move(bed));
    index.push_back(b);
  }
  calibration.runs += read_or_run(c, p, calibration.spec, calibration.cache_dir, beds, hooks, executor);
  std::vector<std::string> changed;
  for (std::size_t b = 0; b < beds.size(); ++b) {
    changed.push_back(beds[b].layer + " " + std::to_string(beds[b].slabs) + " slabs: extra damping ratio " +
                      base::format_number(beds[b].extra_damping_ratio, 3));
    calibration.beds[index[b]] = std::move(beds[b]);
  }
  calibration.wall_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return changed;
}

double CalibratedBed::stroke_min_m() const {
  double lowest = INFINITY;
  for (const auto& p : periods) lowest = std::min(lowest, p.stroke_m);
  return lowest;
}

double CalibratedBed::stroke_max_m() const {
  double highest = 0.0;
  for (const auto& p : periods) highest = std::max(highest, p.stroke_m);
  return highest;
}

const base::Fields<CalibratedBed>& CalibratedBed::fields() {
  using B = CalibratedBed;
  static const auto f =
      base::Fields<B>()
          .field("layer", &B::layer, "", "the layer")
          .field("slabs", &B::slabs, "", "whole slabs in it")
          .field("extra_damping_ratio", &B::extra_damping_ratio, "1",
                 "damping added to every mode in its decay (0: the bed alone)")
          .field("key", &B::key, "", "16 hex digits of the physics the calibration depends on")
          .field("cached", &B::cached, "", "read from the cache, not run now")
          .derived("file", [](const B& b) { return b.file.string(); }, "", "its cache file")
          .derived("periods", [](const B& b) { return b.periods.size(); }, "", "periods of its decay binned")
          .derived("stroke_min_m", [](const B& b) { return b.stroke_min_m(); }, "m", "the smallest stroke its periods passed")
          .derived("stroke_max_m", [](const B& b) { return b.stroke_max_m(); }, "m", "the largest")
          .field("steps", &B::steps, "", "integration steps of its DEM decay")
          .field("energy_error", &B::energy_error, "1", "its energy ledger's relative error")
          .field("wall_time_s", &B::wall_time_s, "s", "wall time of its DEM decay (when it ran)");
  return f;
}

const base::Fields<BedCalibration>& BedCalibration::fields() {
  using C = BedCalibration;
  static const auto f =
      base::Fields<C>()
          .derived("method", [](const C&) { return std::string("dem_decay"); }, "", "how the beds were calibrated")
          .derived("what", [](const C&) { return std::string(C::kWhat); }, "", "what was run")
          .derived("duration_s", [](const C& c) { return c.spec.duration_s; }, "s", "each bed's decay")
          .derived("stiffness_softening", [](const C& c) { return c.spec.stiffness_softening; }, "1",
                   "the DEM's softening in the calibration")
          .derived("strokes_per_decade", [](const C& c) { return c.spec.strokes_per_decade; }, "",
                   "stroke bins per decade of the field")
          .derived("cache_dir", [](const C& c) { return c.cache_dir.string(); }, "", "where the beds are cached")
          .field("runs", &C::runs, "", "beds run now (the others from the cache)")
          .field("beds", &C::beds, "", "each calibrated bed")
          .field("wall_time_s", &C::wall_time_s, "s", "wall time of the calibration");
  return f;
}

}  // namespace pdamp::tasks
