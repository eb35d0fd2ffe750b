// Motion modes of a driven DEM run: the per-run accumulators of the indicators, fed at
// the recorder's block ends by any driver, and the label decided from them.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "pdamp/dem_reference/run_measures.hpp"
#include "pdamp/dem_reference/run_recorder.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace pdamp::dem_reference {

/// Motion modes of docs/theory.md §8.1 (criteria in docs/dem.md "Motion modes").
enum class MotionMode {
  kSolidLike,
  kRollingCollectAndCollide,
  kBouncingCollectAndCollide,
  kScattering,
  kLocalFluidisation,
  kGlobalFluidisation,
  kDecoupled,
};
/// "solid_like", "rolling_collect_and_collide", "bouncing_collect_and_collide",
/// "scattering", "local_fluidisation", "global_fluidisation", "decoupled".
std::string_view to_string(MotionMode mode);

/// The numbers the motion-mode label is decided from (over the analysed periods; x_r is
/// the bed's centre of mass relative to the container centre along the drive, sampled at
/// the block ends; h the clearance of compartment 0). Derivations and thresholds:
/// docs/dem.md "Motion modes".
struct MotionIndicators {
  /// Peak-to-peak travel of x_r over h (≈ 1 when the bed crosses the clearance).
  double relative_stroke_over_clearance = 0.0;
  /// Phase-locked stroke 2|x̂_r(Ω)|/h: peak-to-peak of the component of x_r at the drive
  /// frequency over all analysed periods together (a motion whose phase drifts from
  /// period to period averages out). Ideal collect-and-collide orbits: 0.98 (onset) to
  /// 1.23 (X = 3h); a bed at rest in the inertial frame: 2X/h.
  double phase_locked_stroke = 0.0;
  /// |Σ_p x̂_r,p| / Σ_p |x̂_r,p| over the periods p, in [0, 1]: 1 when every period's
  /// relative motion at Ω has the same phase (≈ 1/√n for a random phase).
  double phase_coherence = 0.0;
  /// Lag of the component of x_r at Ω behind the container position X sin Ωt, degrees in
  /// (−180, 180]: ideal collect-and-collide orbits 149° (onset) to 82° (X = h), 55°
  /// (X = 3h) and 37° (X = 10h); a bed left behind by the container (rolling freely,
  /// decoupled) 180°.
  double phase_lag_deg = 0.0;
  /// Crossings of the clearance per half period: transits of x_r from the outer quarter
  /// of the clearance at one wall (within h/4 of the collected position) to that at the
  /// other, over 2 × analysed periods (1 on a collect-and-collide orbit).
  double crossing_fraction = 0.0;
  /// Correlation of x_r between consecutive periods, in [−1, 1] (informative only: the
  /// chaotic scatter of a many-sphere bed lowers it on a collect-and-collide orbit).
  double period_correlation = 0.0;
  /// Coefficient of variation of the per-period η* (informative only, as above).
  double eta_star_variation = 0.0;
  double apparent_mass_fraction = 0.0;  ///< m_app/m_bed
  /// Particles touching the wall that gravity presses them on (mean fraction, 0 without
  /// gravity): rolling collect-and-collide when >= half the settled fraction.
  double base_contact_fraction = 0.0;
  /// The same fraction of the settled bed before the drive starts (0 without gravity).
  double settled_base_contact_fraction = 0.0;
  /// Particles touching nothing (mean fraction).
  double airborne_fraction = 0.0;
  /// Mean extent of the bed along the drive over its packed extent (1 = packed;
  /// informative only: a container barely longer than the bed caps it).
  double spread_over_packed = 0.0;
  /// Spheres whose rms speed relative to the bed's mean velocity (over the analysed
  /// periods) exceeds V/2, fraction (0: the bed moves as a block; 1: a granular gas).
  double mobile_fraction = 0.0;
  static const base::Fields<MotionIndicators>& fields();
};

/// The drive the indicators are read against.
struct MotionReference {
  /// Ω of the reference motion X sin Ωt (drive time) the phase lag is measured against, rad/s.
  double angular_frequency_rad_s = 0.0;
  double velocity_amplitude_m_s = 0.0;  ///< V: a sphere is mobile above V/2, m/s
  double intensity = 0.0;               ///< Γ = XΩ²/g (fluidisation needs Γ > 1)
};

/// Accumulates the motion-mode indicators over the recorded blocks: built when the
/// drive starts (it takes the settled bed's base contacts then), fed at every block end
/// of a BlockRecorder (contact census, spread, each sphere's velocity fluctuation), and
/// read at the end with the recorder's series and the drive-bin measures. O(particles)
/// per block; allocates nothing after construction.
class MotionModeAccumulator {
 public:
  /// `world_options` are those the world was built with (compartment 0 sets the clearance
  /// reference and the container centre); drive_axis a unit vector.
  MotionModeAccumulator(const World& world, const WorldOptions& world_options, const Vec3& drive_axis);
  /// Samples the world at a block end.
  void sample_block(const World& world);
  /// The indicators over the sampled blocks, from the recorder's bed positions at the
  /// block ends (its whole periods), the measures and the reference drive.
  MotionIndicators indicators(const BlockRecorder& recorder, const DriveBinMeasures& measures,
                              const MotionReference& drive) const;
  /// Checkpoints (checkpoint.hpp): the settled reference and the sums over the blocks so
  /// far; restore throws std::invalid_argument for another bed (sphere count) or non-finite sums.
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  Vec3 axis_;
  Vec3 gravity_m_s2_;
  double bed_mass_kg_;
  double clearance_m_;        ///< compartment 0
  double packed_extent_m_;    ///< compartment 0's inner length along its collect axis − clearance
  double centre_m_;           ///< compartment 0's centre along the drive (body frame)
  double settled_base_fraction_;
  std::int64_t blocks_ = 0;
  double base_sum_ = 0.0, airborne_sum_ = 0.0, spread_sum_ = 0.0;
  std::vector<double> fluctuation_sum_;  ///< per sphere, Σ over blocks of |v_i − v_bed|², m²/s²
};

/// The label of docs/theory.md §8.1 from the indicators (docs/dem.md "Motion modes"): the first
/// that applies.
MotionMode classify_motion(const MotionIndicators& indicators, double eta_star, double intensity);

}  // namespace pdamp::dem_reference
