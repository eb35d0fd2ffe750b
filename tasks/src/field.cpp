// pdamp field as a study (field.hpp).
#include "pdamp/tasks/field.hpp"

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/surrogate/dem_evaluator.hpp"
#include "pdamp/surrogate/measured_import.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

using nlohmann::json;
using base::format_number;
using base::InputError;

surrogate::SweepOptions field_sweep_options(const case_file::Case& c, const std::string& source) {
  const detail::SingleDamper single = detail::single_damper(c, "pdamp field");
  const bool dem = source == "dem";
  surrogate::SweepOptions sweep;
  sweep.source = dem ? surrogate::FieldSource::kDem : surrogate::FieldSource::kFormulas;
  sweep.case_hash = case_file::physics_hash(c, source);
  sweep.model_version = dem ? surrogate::dem_model_version() : 0;
  sweep.approach_amplitude_m = dem ? c.dem.simulation.approach_amplitude_m : 0.0;
  sweep.clearance_m = single.layer.clearance_m;
  sweep.bed_mass_kg = single.layer.bed_mass_kg;
  sweep.threads = dem ? c.field.threads : 1;
  return sweep;
}

std::string check_dem_field(const case_file::Case& c, std::size_t damper, const surrogate::Grid& grid,
                            const surrogate::SweepOptions* sweep, double at_once, bool accept_long_runs) {
  auto options = case_file::dem_options(c, damper, 1.0, 1.0);
  const double clearance_m = c.dampers.at(damper).layers.front().clearance_m;
  options.world.threads = 1;  // as the sweep runs each point
  // Up to 8 nodes per axis, evenly spread with both ends: the options are monotone in
  // the stroke and the frequency (the impact speed grows with both), so the corners
  // hold the extremes, and the work sums scale with the nodes (an estimate of a
  // million-node grid node by node took minutes).
  const auto sampled = [](std::size_t n) {
    std::vector<std::size_t> picks;
    const std::size_t m = std::min<std::size_t>(n, 8);
    for (std::size_t j = 0; j < m; ++j) picks.push_back(m == 1 ? 0 : j * (n - 1) / (m - 1));
    return picks;
  };
  double wall_time_s = 0.0, particle_steps = 0.0;
  std::size_t evaluated = 0;
  dem_reference::RunEstimate largest;
  for (const std::size_t i0 : sampled(grid.axis0.size())) {
    for (const std::size_t i1 : sampled(grid.axis1.size())) {
      const auto drive = surrogate::drive_point(grid, i0 * grid.axis1.size() + i1, clearance_m);
      const auto point = surrogate::dem_point_options(options, drive.frequency_hz, drive.amplitude_m);
      const auto e = check_dem_run(c, damper, point);
      if (evaluated++ == 0) check_dem_placement(c, damper, point);  // the same bed at every node
      check_wall_time(c, e.wall_time_s, "a point of the DEM field sweep", "/dem",
                      "fewer /dem/analysed_periods or /dem/transient_periods, a larger /dem/time_step_s, or fewer "
                      "particles",
                      accept_long_runs);
      wall_time_s += e.wall_time_s;
      particle_steps += e.particle_steps;
      if (e.memory_bytes > largest.memory_bytes) largest = e;
    }
  }
  const double per_node = static_cast<double>(grid.size()) / static_cast<double>(evaluated);
  wall_time_s *= per_node;
  particle_steps *= per_node;
  at_once = std::min<double>(at_once, static_cast<double>(grid.size()));
  check_memory(c, damper, largest, at_once);
  std::size_t pending = grid.size();
  try {
    if (sweep != nullptr) pending = surrogate::pending_sweep_points(grid, *sweep);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, "/field", e.what());
  }
  const double share = static_cast<double>(pending) / static_cast<double>(grid.size());
  return std::to_string(pending) + " of " + std::to_string(grid.size()) + " points to run, " +
         format_number(share * particle_steps, 3) + " particle-steps, about " +
         format_number(share * wall_time_s / at_once, 2) + " s with " + format_number(at_once, 3) +
         " points at once; memory about " + megabytes(at_once * static_cast<double>(largest.memory_bytes));
}

FieldPlan plan_field(const case_file::Case& c, const FieldOptions& options, const base::Executor& executor) {
  FieldPlan plan;
  plan.options = options;
  plan.grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);
  plan.sweep = field_sweep_options(c, options.source);
  plan.sweep.shard_index = options.shard_index;
  plan.sweep.shard_count = options.shard_count;
  plan.sweep.results_path = options.results_log;
  if (options.source == "dem") {
    plan.estimate = check_dem_field(c, 0, plan.grid, &plan.sweep, executor.concurrency(c.field.threads),
                                    options.accept_long_runs);
  } else {
    try {
      (void)surrogate::pending_sweep_points(plan.grid, plan.sweep);  // a stale log: refused before any work
    } catch (const std::invalid_argument& e) {
      throw InputError(c.path, "/field", e.what());
    }
  }
  return plan;
}

namespace {

/// The scattered-state law fitted to a measured or DEM field's points below the onset; a
/// fit that cannot be made is a warning.
void fit_scattered(const case_file::Case& c, FieldResult& r) {
  if (r.field.provenance.source == surrogate::FieldSource::kFormulas) return;
  const auto& damper = c.dampers.front();
  try {
    const auto samples = surrogate::scattered_samples(r.field, damper.model,
                                                      case_file::layer_model_options(damper, damper.layers.front()));
    r.scattered_fit = surrogate::fit_scattered_law(
        samples, "pdamp field --source " + std::string(surrogate::to_string(r.field.provenance.source)) + ", case " + c.name);
  } catch (const std::exception& e) {
    r.warnings.push_back(std::string("scattered-state fit not made: ") + e.what());
  }
}

}  // namespace

FieldResult run_field(const case_file::Case& c, const FieldPlan& plan, base::RunHooks& hooks, base::Executor& executor) {
  const detail::SingleDamper single = detail::single_damper(c, "pdamp field");
  const bool dem = plan.options.source == "dem";
  surrogate::PointEvaluator evaluator;
  if (dem) {
    auto options = case_file::dem_options(c, 0, 1.0, 1.0);
    options.world.threads = 1;  // the sweep runs points in parallel instead
    evaluator = surrogate::dem_evaluator(options);
  } else {
    evaluator = surrogate::formula_evaluator(single.damper.model, single.layer.clearance_m, single.layer.bed_mass_kg,
                                             case_file::layer_model_options(single.damper, single.layer));
  }
  const auto& grid = plan.grid;
  surrogate::SweepOptions sweep = plan.sweep;
  base::Jobs<surrogate::FieldPoint> jobs(executor, [&](std::size_t k) {
    const auto drive = surrogate::drive_point(grid, k, sweep.clearance_m);
    return evaluator(drive.frequency_hz, drive.amplitude_m);
  });
  sweep.threads = executor.concurrency(sweep.threads);
  if (dem) {
    hooks.note(plan.options.label + ": " + plan.estimate +
               (plan.options.sharded
                    ? " (shard " + std::to_string(plan.options.shard_index) + "/" + std::to_string(plan.options.shard_count) + ")"
                    : "") +
               (executor.processes() > 1 ? ", spread over " + std::to_string(executor.processes()) + " MPI ranks" : ""));
  }
  // A DEM sweep reports its points and stops on request; a formulas sweep takes microseconds.
  base::LabelledHooks labelled(hooks, plan.options.label);
  const auto result =
      surrogate::run_sweep(grid, [&](std::size_t k) { return jobs(k); }, sweep, dem ? labelled : base::silent_hooks());
  jobs.end();  // the field is this process's alone (some points from its log): the others' part ends
  FieldResult out;
  out.case_name = c.name;
  out.field = result.field;
  out.summary = result.summary;
  out.sweep_report = result.summary.brief_report();
  out.warnings = result.summary.warnings;
  out.mpi = jobs.balance();
  if (!plan.options.sharded) fit_scattered(c, out);  // a shard has no field of its own
  return out;
}

FieldResult import_measured_field(const case_file::Case& c, const std::filesystem::path& csv, base::Executor& executor) {
  executor.primary_only();
  const detail::SingleDamper single = detail::single_damper(c, "pdamp field");
  surrogate::MeasuredImportOptions options;
  options.clearance_m = single.layer.clearance_m;
  options.bed_mass_kg = single.layer.bed_mass_kg;
  options.frequency_spacing = c.field.axis0.spacing;
  options.amplitude_spacing = c.field.axis1.spacing;
  options.case_hash = case_file::physics_hash(c, "measured");
  FieldResult out;
  out.case_name = c.name;
  try {
    out.field = surrogate::import_measured_csv(csv, options);
  } catch (const std::invalid_argument& e) {
    throw InputError("--measured", "", e.what());
  }
  fit_scattered(c, out);
  return out;
}

FieldResult merge_field(const case_file::Case& c, const std::string& source, const std::vector<std::filesystem::path>& logs) {
  (void)detail::single_damper(c, "pdamp field merge");
  const auto grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);
  const auto result = surrogate::merge_sweep_shards(grid, field_sweep_options(c, source), logs, c.path);
  FieldResult out;
  out.case_name = c.name;
  out.field = result.field;
  out.summary = result.summary;
  out.sweep_report = "merged " + std::to_string(logs.size()) + " shard files: " + std::to_string(result.summary.points_total) +
                     " points (" + std::to_string(result.summary.points_failed) + " failed)";
  out.warnings = result.summary.warnings;
  fit_scattered(c, out);
  return out;
}

}  // namespace pdamp::tasks
