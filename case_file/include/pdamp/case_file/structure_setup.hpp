// The runtime models of a format-2 case (docs/cases.md "Format 2"): the structure's modal
// model and its dampers, each layer with the loss model a structure solver asks.
//
// How a damper's shapes convert (one direction, from the case):
//   case_file::DamperSpec (case.hpp: what the case file says, read and derived once)
//     -> structure::Damper           structure_setup(): site, drive, container mass, and per
//                                    layer the loss model of --method (the averaging solvers)
//     -> structure::CosimulationDamper  cosimulation_damper(): the same site and container, the
//                                    bed as a DEM World (the DEM in the loop)
//     -> optimizer::LayerCandidate   filling_ratio_problem() (filling_ratio_problem.hpp): each
//                                    layer's slabs, sphere mass and length for the optimiser
//   and back: a design of slabs becomes a case of its own with with_design() (case.hpp),
//   read again by the reader, so its beds and hashes are derived in one place.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/case_file/case.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::case_file {

/// Where the layers' η*(f, X) and apparent mass come from (`--method`).
enum class LossMethod {
  kFormulas,  ///< the closed forms of each layer (its model, clearance and constants)
  kField,     ///< each layer's effective field (`field_file`), looked up at its own clearance
};
std::string_view to_string(LossMethod method);

/// Largest modal mass ratio of the beds (μ_j = Σ_d b_dj² m_bed,d / m_j, any kept mode) below
/// which structure_setup stays silent: above it the first-harmonic coupling is off by more
/// than 6 % and its warning sends the user to the DEM in the loop (docs/theory.md §7.8).
inline constexpr double kMaxModalMassRatio = 0.1;

struct StructureSetup {
  structure::ModalModel modal;               ///< beam: its finite-element modes; modal data: as read
  /// Beam: the beam as analysed, the dampers' weights added as carried weights (their
  /// geometric stiffness); static deflections must use it. Empty for modal data.
  std::optional<structure::BeamModel> beam;
  int rigid_modes_dropped = 0;               ///< beam: rigid-body modes at 0 Hz not kept
  std::vector<structure::Damper> dampers;    ///< in case order, layers in case order
  /// One sentence each: the settled beds', a field reused at another clearance, a modal mass
  /// ratio above kMaxModalMassRatio.
  std::vector<std::string> warnings;
  /// kField: "damper/layer" of each DEM field built from rest (the ascending branch; a
  /// decay or a down sweep follows the descending one, docs/dem.md "Approach").
  std::vector<std::string> fields_from_rest;
};

/// The case's beam with the weight (container and beds) of every damper except
/// `without_damper` carried at its site: what loads the geometric stiffness.
structure::BeamModel loaded_beam(const Case& c, std::optional<std::size_t> without_damper = {});

/// Builds the structure and its dampers; CaseError (exit 2) for a case without a
/// structure, a layer without `field_file` under kField, or an unreadable field file.
StructureSetup structure_setup(const Case& c, LossMethod method);

/// Modal amplitudes q_j(0) of a decay's initial state: a released static load (a beam:
/// its exact static deflection projected on the kept modes; modal data: the kept modes'
/// static response) or the given values. CaseError naming /task/initial_state otherwise.
Eigen::VectorXd initial_modal_amplitudes(const Case& c, const StructureSetup& setup, const DecayTask& task);

/// Damper `damper_index` of the case as a co-simulation damper (`--method dem`,
/// docs/cosimulation.md): its site, drive direction and empty container mass, and its bed
/// as the World of dem_options(c, damper_index, ...).world (one compartment per layer; the
/// case's `dem` materials, contact, softening, integration, seed and threads; gravity in the
/// container frame from the damper). The container's drive axis is the damper's
/// `drive_axis`; its rotation axis (the structure's z in the container frame) is chosen:
///  - gravity with a part g_perp across the drive (> 1% of |g|): on a beam with
///    `axial_gravity_m_s2` != 0 gravity lies in the structure's plane, so z is the unit
///    vector drive x g_perp; otherwise gravity is taken to be out of the plane and z is
///    -g_perp/|g_perp| (the structure's z points up);
///  - otherwise (no gravity, or gravity along the drive) the container axis after the
///    drive axis in the cycle x -> y -> z -> x, plus one (drive x: z; y: x; z: y).
/// CaseError naming the damper for a DEM option its World refuses.
structure::CosimulationDamper cosimulation_damper(const Case& c, std::size_t damper_index);

}  // namespace pdamp::case_file
