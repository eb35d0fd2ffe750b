// CSV tables and gnuplot pictures of the structure commands (pdamp modes, frf, decay):
// the data files and the scripts that draw them (docs/structure_cli.md lists the columns).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/report/output_dir.hpp"
#include "pdamp/structure/backbone.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/structure/harmonic_balance.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::report {

/// What modes.csv holds: one row per reported mode (1-based in the file).
struct ModeTable {
  std::vector<double> frequency_hz;       ///< with the empty containers attached, Hz
  std::vector<double> bare_frequency_hz;  ///< of the structure alone, Hz
  std::vector<double> damping_ratio;      ///< structural ζ_j of the modal model
  std::vector<std::string> damper_names;
  Eigen::MatrixXd mass_ratio;             ///< modes x dampers: μ_dj = b_dj² Σ_l m_bed,l / m_j
  std::vector<structure::PointModeShape> points;  ///< shapes (columns: modes of the model)
};
void write_modes_table(OutputDir& out, const ModeTable& table);

/// backbone_mode<j>.csv for every backbone (j = mode + 1) and backbone.gp/png/svg:
/// ζ_add(X) and the damped natural frequency f(X) per mode, X on a log axis.
/// `layer_names` label the η* columns. `dem_check_file` (a CSV of mode, frequency_hz,
/// damper_amplitude_m, predicted_damping_ratio, dem_damping_ratio, ... with a header; empty:
/// none) adds its decays' ζ_add to the damping panel as points. Returns warnings (gnuplot
/// missing or failing).
std::vector<std::string> write_backbone_files(OutputDir& out, const std::vector<structure::Backbone>& backbones,
                                              const std::vector<std::string>& layer_names, const std::string& title,
                                              const std::string& dem_check_file = "");

/// frf.csv (one row per frequency: the linear response without beds, then every root and
/// every state held at a jump), frf_branches.csv (one row per root, grouped by branch,
/// a blank line between branches) and frf.gp/png/svg: |output| with and without the beds,
/// every branch, unstable parts dashed, jump frequencies marked, log y.
std::vector<std::string> write_frf_files(OutputDir& out, const structure::FrequencyResponse& response,
                                         const std::vector<std::string>& damper_names,
                                         const std::string& magnitude_label, const std::string& title);

/// The decay's reference without particles (the containers empty): time_s, envelope_m.
/// The decay plots below draw it, so it is written first.
inline constexpr const char* kWithoutBedsCsv = "decay_without_beds.csv";
void write_without_beds_csv(OutputDir& out, const structure::FreeDecay& without_beds);

/// decay.csv (time, the envelope at the threshold point, each mode's amplitude, each
/// damper's amplitude, energies, each layer's cumulative dissipated energy and power) and
/// decay.gp/png/svg: the envelope with threshold and settling time (log y), and the
/// envelope without particles, over the per-layer dissipated energies.
std::vector<std::string> write_decay_files(OutputDir& out, const structure::FreeDecay& decay,
                                           const std::vector<std::string>& damper_names, const std::string& title);

/// The DEM frequency responses' reference without particles (the containers empty):
/// frequency_hz, then magnitude_<output> and phase_deg_<output>. The DEM FRF plots below
/// draw it, so it is written first.
inline constexpr const char* kFrfWithoutBedsCsv = "frf_without_particles.csv";
void write_frf_without_beds_csv(OutputDir& out, const structure::FrequencyResponse& without_beds);

/// decay_dem.gp/png/svg for decay_dem.csv (written by pdamp decay --method dem: time_s,
/// site_displacement_m_<damper> x dampers, envelope_m, ...): the first damper's site
/// displacement with offset ± envelope, offset ± threshold, the settling time and the
/// envelope without particles.
std::vector<std::string> write_decay_dem_plot(OutputDir& out, double offset_m, double threshold_m, double settling_time_s,
                                              std::size_t dampers, const std::string& title);

/// frf_dem.gp/png/svg for frf_dem.csv (pdamp frf --method dem: frequency_hz, then
/// magnitude_<d>, phase_deg_<d> per damper, then the first damper's spread): |output| per
/// frequency (log y), the first with its spread as error bars.
std::vector<std::string> write_frf_dem_plot(OutputDir& out, const std::vector<std::string>& damper_names,
                                            const std::string& magnitude_label, const std::string& title);

/// frf_dem_sweep.gp/png/svg for frf_dem_sweep.csv (pdamp frf --method dem --dem-signal
/// linear: sweep, time_s, frequency_hz, then magnitude_<d>, phase_deg_<d> per damper): each
/// cycle's |output| against its frequency (log y), up solid and down dashed.
std::vector<std::string> write_frf_dem_sweep_plot(OutputDir& out, const std::vector<std::string>& damper_names,
                                                  const std::string& magnitude_label, const std::string& title);

/// One DEM point of pdamp frf --compare: the stepped sine's first harmonic and its spread.
struct CompareDemPoint {
  double frequency_hz = 0.0;
  double magnitude = 0.0;
  double spread = 0.0;  ///< sample standard deviation over the analysed periods (0 if not defined)
  std::string sweep;    ///< "up" or "down"
  bool converged = true;  ///< its transient converged (else drawn apart, stability "dem_unconverged")
};

/// frf_compare.csv (source,branch,frequency_hz,stability,magnitude,magnitude_spread: the
/// formulas' and the field's roots by branch, unstable ones marked, then the DEM points; a
/// blank line between branches) and frf_compare.gp/png/svg: the first output of each source
/// on one log-y axis, formulas and field as lines (unstable parts dashed), DEM as points
/// with error bars. `field` may be null (skipped).
std::vector<std::string> write_frf_compare_files(OutputDir& out, const structure::FrequencyResponse& formulas,
                                                 const structure::FrequencyResponse* field,
                                                 const std::vector<CompareDemPoint>& dem,
                                                 const std::string& magnitude_label, const std::string& title);

}  // namespace pdamp::report
