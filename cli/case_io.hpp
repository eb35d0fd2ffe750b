// The case file format (docs/cases.md): JSON -> validated option structs, and the
// resolved case with every default filled in (`pdamp validate`).
#pragma once

#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/formulas/bed_packing.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "pdamp/surrogate/grid.hpp"
#include "errors.hpp"

namespace pdamp::cli {

/// Tasks `pdamp run` knows.
enum class Task { kDamperDesign };

struct DamperSpec {
  formulas::DamperModel model = formulas::DamperModel::kAuto;
  formulas::Container container;
  int drive_axis = 0;
  formulas::Vec3 gravity_m_s2{0.0, 0.0, -formulas::kStandardGravity};
  int particle_count = 0;
  double particle_radius_m = 0.0;
  std::string particle_material = "steel";
  /// ISO 3290 lot variation of the ball diameter (dem_reference::ParticleGroupOptions).
  double lot_diameter_variation_m = dem_reference::ParticleGroupOptions{}.lot_diameter_variation_m;
  formulas::LatticePacking packing;
  formulas::ModelOptions model_options;
  // Derived on load:
  formulas::LatticeBed bed;     ///< the collected lattice and its clearance
  double clearance_m = 0.0;     ///< the bed's h, or the explicit `clearance_m` override
  double bed_mass_kg = 0.0;
};

struct ExcitationSpec {
  double frequency_hz = 0.0;
  std::optional<double> amplitude_m;  ///< the operating stroke, if the case has one
};

struct DesignSpec {
  std::optional<double> target_stroke_m;
  double sweep_min_over_clearance = 0.05;
  double sweep_max_over_clearance = 1.5;
  int sweep_points = 301;
};

struct BufferSpec {
  std::string layer_material;
  formulas::BufferDesignInput input;  ///< particle data filled from the damper
};

/// The reference DEM of the case's damper (docs/cases.md, `dem`); amplitude and
/// frequency are set per run from the excitation or the command line.
struct DemSpec {
  dem_reference::DamperSimulationOptions simulation;
  double stiffness_softening = 1.0;  ///< factor on every Young's modulus in the DEM only
};

/// The effective-field grid of `pdamp field` (docs/cases.md, `field`).
struct FieldSpec {
  surrogate::GridAxes axes = surrogate::GridAxes::kFrequencyAmplitude;
  surrogate::AxisRange axis0;  ///< frequency_hz or intensity
  surrogate::AxisRange axis1;  ///< amplitude_m or stroke_over_clearance
  int threads = 2;             ///< DEM points run at once
};

struct Case {
  std::string path;
  std::string name;
  std::string description;
  Task task = Task::kDamperDesign;
  std::map<std::string, formulas::Material> materials;
  DamperSpec damper;
  ExcitationSpec excitation;
  DesignSpec design;
  std::optional<BufferSpec> buffer;
  DemSpec dem;
  FieldSpec field;
  nlohmann::json resolved;  ///< the case with every default resolved and derived values added
};

/// Reads and validates a case; InputError (exit 2) names file, JSON pointer and rule.
Case load_case(const std::string& path);

std::string_view to_string(Task task);

/// "layered" or "half_space" (the contact law of the buffer sizing); InputError naming
/// `where` (a file or a flag) and `key` otherwise.
formulas::BufferModel buffer_model(const std::string& name, const std::string& where, const std::string& key);

/// A line of dem_reference's validate() ("integration.time_step_s = 0.001: ...") as
/// the case's error: the internal option name becomes the JSON pointer of the case key
/// it comes from (/dem/time_step_s, /dem/inner_structures/pins/0, ...).
InputError dem_input_error(const Case& c, const std::string& problem);

/// The case's DEM options for one operating point (stroke X, frequency f).
dem_reference::DamperSimulationOptions dem_options(const Case& c, double amplitude_m, double frequency_hz);

}  // namespace pdamp::cli
