// pdamp dem's run handed to LIGGGHTS-PUBLIC 3.8 (docs/liggghts.md): an input deck that runs
// the case's damper as pdamp dem does (geometry, the bed at pdamp's own initial positions,
// materials, Hertz-Mindlin contacts, gravity, time step, settling, the drive x = X sin(Ωt)),
// and the import of what that deck writes into pdamp dem's measures, computed with pdamp's
// own drive-bin measure (dem_reference::DriveBinMeasure). pdamp never starts LIGGGHTS: the
// user (or a cluster job) runs the deck.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"
#include "pdamp/dem_reference/run_measures.hpp"
#include "pdamp/tasks/dem_run.hpp"

namespace pdamp::tasks {

/// The files the deck writes while LIGGGHTS runs, in its folder.
inline constexpr const char* kLiggghtsForceFile = "force.txt";
inline constexpr const char* kLiggghtsEnergyFile = "energy.txt";
/// The export record the import reads (everything it needs besides the two files above).
inline constexpr const char* kLiggghtsExportRecord = "pdamp_export.json";
/// The deck's main input file.
inline constexpr const char* kLiggghtsInputFile = "in.pdamp";

/// An exported deck: its files (name, content) and the record, also one of the files.
struct LiggghtsDeck {
  std::vector<std::pair<std::string, std::string>> files;  ///< in.pdamp, particles.data, container.stl, README.txt
  nlohmann::json record;                                   ///< pdamp_export.json
  std::vector<std::string> warnings;
};

/// The deck of pdamp dem's run of the case at the options' stroke, frequency and analysed
/// periods (defaults: the case's), with the run's own time step, settling steps and
/// transient periods (plan_dem: every check pdamp dem makes, before any output). What
/// LIGGGHTS cannot run as pdamp does is refused (InputError naming the case key): more
/// than one compartment, inner structures, wall layers, an approach from above, a
/// restitution table over impact speed. `pdamp_version` is recorded.
LiggghtsDeck export_liggghts(const case_file::Case& c, const DemRunOptions& options, const std::string& pdamp_version);

/// pdamp dem's measures from a LIGGGHTS run of an exported deck.
struct LiggghtsImport {
  nlohmann::json record;  ///< the export record as read
  std::string case_name;
  double amplitude_m = 0.0;
  double frequency_hz = 0.0;
  double bed_mass_kg = 0.0;
  double time_step_s = 0.0;
  std::int64_t steps_per_period = 0;
  int samples_per_period = 0;
  int analysed_periods = 0;
  /// The drive-bin measures over the analysed periods (η*, its standard error over the
  /// per-period values, E_diss, apparent mass), from the force samples.
  dem_reference::DriveBinMeasures measures;
  /// Container work over the analysed periods, Σ F̄_k·Δx_c,k (the sample's mean force of the
  /// container on the bed times the container's displacement over the sample), J. With the
  /// container's harmonic motion this is the drive bin's n·2π·E_diss again, not an
  /// independent check: LIGGGHTS counts no dissipation in its contacts, so pdamp dem's
  /// energy balance (work against counted dissipation) has no counterpart here.
  double container_work_j = 0.0;
  double delta_kinetic_j = 0.0;    ///< translational + rotational, end minus start of the analysis, J
  double delta_potential_j = 0.0;  ///< −m_bed g·Δx_com, J
  std::vector<std::string> warnings;
};

/// Reads DIR/pdamp_export.json, DIR/force.txt and DIR/energy.txt. InputError naming the
/// file and what is wrong (missing, not of this export, a line that is not numbers, a step
/// out of sequence, fewer samples than the run writes: LIGGGHTS has not finished).
LiggghtsImport import_liggghts(const std::filesystem::path& dir);

/// The keys of pdamp dem --json that the import can fill (docs/liggghts.md "Import").
nlohmann::json to_json(const LiggghtsImport& result);

/// The coefficient of the LIGGGHTS hertz model's normal damping in pdamp's form
/// γ_n √(m*K) δ^{1/4} δ̇ (docs/dem.md "Contact laws"): LIGGGHTS damps with
/// 2√(5/6)·|β|·√(S_n m*), S_n = 2E*√(R*δ), β = ln ε/√(ln²ε + π²), which is γ_n = √5·|β(ε)|.
double liggghts_damping_coefficient(double restitution);

}  // namespace pdamp::tasks
