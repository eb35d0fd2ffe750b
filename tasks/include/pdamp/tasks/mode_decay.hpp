// One mode's free decay, alone from a given amplitude, with one damper at a given site: the
// damping ratio its beds add by their loss models (the averaged decay) and by the DEM in the
// loop, measured alike. The DEM check of a placement (each target mode at the chosen site and
// another) and of a structure's damping against amplitude (task kind modes, `dem_check`).
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/base/record.hpp"
#include "pdamp/base/run_hooks.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::tasks {

/// A mode's bed is taken on the descending branch, as a decay that began higher passes it: a
/// calibration's points are approached from this factor above its largest stroke, and a
/// forced start (ModeDecayWindow::forced_start_periods) rises to it before the release. 25 %:
/// above the stroke, close enough to stay in its regime (a grid step of a coarse grid, a
/// factor 10 at one stroke per decade, would not).
inline constexpr double kDescendingBranchFactor = 1.25;

/// How a mode's decay is measured: its length and the amplitude it is measured down to.
struct ModeDecayWindow {
  int periods = 40;                 ///< the decay's length in periods of the mode, >= 4
  double amplitude_fraction = 0.5;  ///< measured down to this fraction of the first period, (0, 1)
  /// The DEM's beds driven this many periods in the mode's motion before the release, rising to
  /// kDescendingBranchFactor times the start half-way (ForcedStart); 0: released from the beds as placed.
  int forced_start_periods = 0;
};

/// One mode's decay from rest at modal amplitude a (q_j(0) = a, every other mode 0): the
/// damping ratio the beds add by the averaged decay (structure::free_decay) and by the DEM in
/// the loop (dem_decay), each measured by modal_decay_damping_ratio on the mode itself and
/// less the same averaged decay with the containers empty.
struct ModeDecayCheck {
  int mode = 0;                          ///< 0-based
  double frequency_hz = 0.0;             ///< the frequency the periods are counted in
  double damper_amplitude_m = 0.0;       ///< the damper's stroke at the start, |b_j| a, m
  double predicted_damping_ratio = NAN;  ///< ζ_add of the averaged decay
  double dem_damping_ratio = NAN;        ///< ζ_add of the DEM decay
  double bare_damping_ratio = NAN;       ///< ζ of the decay with the containers empty (subtracted)
  double relative_difference = NAN;      ///< (predicted − DEM)/DEM
  /// The DEM decay's last whole period over its first (1: no decay). The decay ends early, at
  /// the first period below 0.9 of the measure's fraction (nothing later enters the measure).
  double dem_final_fraction = NAN;
  double wall_time_s = 0.0;              ///< of the DEM decay
  /// (predicted − DEM)/DEM of the mode's whole damping ratio, bare plus added: what a design
  /// gets (an added ratio far below the structure's own is small in both, and its relative
  /// difference says little).
  double whole_relative_difference() const {
    return (predicted_damping_ratio - dem_damping_ratio) / (bare_damping_ratio + dem_damping_ratio);
  }
  static const base::Fields<ModeDecayCheck>& fields();
};

/// Mode `mode` of `modal` released at modal amplitude `modal_amplitude` with `damper` at point
/// `site` (its bed: the case's damper `damper_index` as a DEM world), over window.periods
/// periods of `frequency_hz`. Progress and the DEM's estimate under `label`; `periods_pointer`
/// names the case key to shorten when the run is estimated too long.
ModeDecayCheck mode_decay_check(const case_file::Case& c, std::size_t damper_index, const structure::ModalModel& modal,
                                structure::Damper damper, const std::string& site, int mode, double modal_amplitude,
                                double frequency_hz, const ModeDecayWindow& window, const std::string& label,
                                const std::string& periods_pointer, base::RunHooks& hooks);

/// The damping ratio of one mode's decay: the per-period largest |q| of the mode (periods of
/// 1/frequency_hz from t = 0) while it stays at or above `fraction` of the first, fitted as
/// ln|q| = a − ζ·2πf·t (least squares); NaN with fewer than two periods.
double modal_decay_damping_ratio(const std::vector<double>& time_s, const Eigen::VectorXd& q, double frequency_hz,
                                 double fraction);

}  // namespace pdamp::tasks
