// What a co-simulation run needs before its first step (cosimulation_plan.hpp): the run's
// options as one struct and their checks, the dampers' checks, the modal arrays with the
// containers, the excitation's shapes and the common step (docs/cosimulation.md §1-3).
#include "cosimulation_plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <initializer_list>
#include <numbers>
#include <stdexcept>

#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/drive_time_step.hpp"
#include "pdamp/structure/damper_coupling.hpp"

namespace pdamp::structure {

namespace {

namespace dem = pdamp::dem_reference;
using base::format_number;
using detail::energy_terms;
using detail::harmonic;
using detail::join;
using detail::kTwoPi;
using detail::ledger_error;
using detail::plan_step;
using detail::prepare;
using detail::Prepared;
using detail::start_vector;
using detail::StepPlan;
using detail::sweeping;
using detail::validate_inputs;

/// Unit vectors to this relative tolerance (inputs from JSON carry ~1e-9).
constexpr double kUnitTolerance = 1e-6;

const PointModeShape* find_point(const ModalModel& model, const std::string& name) {
  for (const auto& p : model.points)
    if (p.name == name) return &p;
  return nullptr;
}

double norm3(const dem::Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
double dot3(const dem::Vec3& a, const dem::Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
/// "(x, y, ...)", 12 significant digits each. Appended piece by piece: GCC 12 flags
/// "(" + std::string with a false -Wrestrict.
std::string coordinates(std::initializer_list<double> values) {
  std::string text = "(";
  for (const double value : values) {
    if (text.size() > 1) text += ", ";
    text += format_number(value, 12);
  }
  text += ')';
  return text;
}
std::string vec3(const dem::Vec3& v) { return coordinates({v[0], v[1], v[2]}); }
std::string vec2(const Eigen::Vector2d& v) { return coordinates({v.x(), v.y()}); }

}  // namespace

namespace detail {

double sweep_cycle_time(double f0, double rate, double cycles) {
  return 2.0 * cycles / (f0 + std::sqrt(std::max(0.0, f0 * f0 + 2.0 * rate * cycles)));
}

void bed_measures(std::complex<double> force_hat, std::complex<double> y, double omega, double m_bed,
                  std::vector<double>& eta_star, std::vector<double>& apparent_mass_fraction) {
  const std::complex<double> velocity = std::complex<double>(0.0, omega) * y;
  const std::complex<double> f_conj_v = force_hat * std::conj(velocity);
  const double v2 = std::norm(velocity);
  const bool defined = m_bed > 0.0 && v2 > 0.0;
  constexpr double undefined = std::numeric_limits<double>::quiet_NaN();
  eta_star.push_back(defined ? (0.5 * f_conj_v.real() / omega) / (0.5 * m_bed * v2) : undefined);
  apparent_mass_fraction.push_back(defined ? f_conj_v.imag() / (omega * v2 * m_bed) : undefined);
}

std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : "\n") + l;
  return out;
}

}  // namespace detail

dem::Matrix3 rotation_about(const dem::Vec3& k, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad), t = 1.0 - c;
  return {t * k[0] * k[0] + c,        t * k[0] * k[1] - s * k[2], t * k[0] * k[2] + s * k[1],
          t * k[0] * k[1] + s * k[2], t * k[1] * k[1] + c,        t * k[1] * k[2] - s * k[0],
          t * k[0] * k[2] - s * k[1], t * k[1] * k[2] + s * k[0], t * k[2] * k[2] + c};
}

std::vector<std::string> CosimulationDamper::validate(const ModalModel& model) const {
  std::vector<std::string> problems;
  if (!find_point(model, point)) problems.push_back("point = \"" + point + "\": must name a point of the modal model");
  if (!(std::abs(drive_direction.norm() - 1.0) <= kUnitTolerance))
    problems.push_back("drive_direction = " + vec2(drive_direction) + ": must be a unit vector");
  if (!(container_mass_kg >= 0.0 && std::isfinite(container_mass_kg)))
    problems.push_back("container_mass_kg = " + format_number(container_mass_kg, 12) + ": must be >= 0 and finite");
  if (!(container_rotary_inertia_kg_m2 >= 0.0 && std::isfinite(container_rotary_inertia_kg_m2)))
    problems.push_back("container_rotary_inertia_kg_m2 = " + format_number(container_rotary_inertia_kg_m2, 12) +
                       ": must be >= 0 and finite");
  const bool drive_unit = std::abs(norm3(container_drive_axis) - 1.0) <= kUnitTolerance;
  const bool rotation_unit = std::abs(norm3(container_rotation_axis) - 1.0) <= kUnitTolerance;
  if (!drive_unit) problems.push_back("container_drive_axis = " + vec3(container_drive_axis) + ": must be a unit vector");
  if (!rotation_unit)
    problems.push_back("container_rotation_axis = " + vec3(container_rotation_axis) + ": must be a unit vector");
  if (drive_unit && rotation_unit && !(std::abs(dot3(container_drive_axis, container_rotation_axis)) <= kUnitTolerance))
    problems.push_back("container_rotation_axis = " + vec3(container_rotation_axis) +
                       ": must be perpendicular to container_drive_axis " + vec3(container_drive_axis));
  for (auto& line : world.validate("world.")) problems.push_back(std::move(line));
  return problems;
}

const CosimulationSettings& settings_of(const CosimulationRun& run) {
  return std::visit([](const auto& r) -> const CosimulationSettings& { return r; }, run);
}

std::vector<std::string> validate(const CosimulationRun& run, const ModalModel& model) {
  return detail::run_options(run).validate(model);
}

namespace detail {

RunOptions run_options(const CosimulationRun& run) {
  RunOptions o;
  static_cast<CosimulationSettings&>(o) = settings_of(run);
  if (const auto* decay = std::get_if<DecayRun>(&run)) {
    o.kind = RunOptions::Kind::kDecay;
    o.duration_s = decay->duration_s;
  } else if (const auto* steady = std::get_if<SteadyStateRun>(&run)) {
    o.kind = RunOptions::Kind::kSteadyState;
    o.excitation = steady->excitation;
    o.excitation_phase_rad = steady->excitation_phase_rad;
    o.transient_periods = steady->transient_periods;
    o.min_transient_periods = steady->min_transient_periods;
    o.analysed_periods = steady->analysed_periods;
    o.settle_until_stable = steady->settle_until_stable;
    o.stable_tolerance = steady->stable_tolerance;
  } else {
    const auto& sweep = std::get<SweepRun>(run);
    o.kind = RunOptions::Kind::kSweep;
    o.excitation = sweep.excitation;
    o.excitation_phase_rad = sweep.excitation_phase_rad;
    o.sweep_end_frequency_hz = sweep.sweep_end_frequency_hz;
    o.duration_s = sweep.duration_s;
  }
  return o;
}

std::vector<std::string> RunOptions::validate(const ModalModel& model) const {
  std::vector<std::string> p;
  const std::string at = "cosimulation.";
  const Eigen::Index modes = model.mode_count();
  const auto& e = excitation;
  if (kind != Kind::kDecay && !harmonic(e))
    p.push_back(at + "excitation.kind = free decay: a harmonic run is driven by a base translation or a point force");
  if (kind == Kind::kSweep && sweep_end_frequency_hz == 0.0)
    p.push_back(at + "sweep_end_frequency_hz = 0: must be in [0.01, 10000] Hz (a linear sweep)");
  if (harmonic(e)) {
    if (!(std::abs(e.direction.norm() - 1.0) <= kUnitTolerance))
      p.push_back(at + "excitation.direction = " + vec2(e.direction) + ": must be a unit vector");
    if (!(e.amplitude > 0.0 && std::isfinite(e.amplitude)))
      p.push_back(at + "excitation.amplitude = " + format_number(e.amplitude, 12) +
                  ": must be > 0 and finite (m or N)");
    if (!(e.frequency_hz >= dem::limits::kMinFrequency_hz && e.frequency_hz <= dem::limits::kMaxFrequency_hz))
      p.push_back(at + "excitation.frequency_hz = " + format_number(e.frequency_hz, 12) +
                  ": must be in [0.01, 10000] Hz");
    if (e.kind == CosimulationExcitationKind::kPointForce && !find_point(model, e.point))
      p.push_back(at + "excitation.point = \"" + e.point + "\": must name a point of the modal model");
    if (e.kind == CosimulationExcitationKind::kBaseTranslation && model.base_participation.cols() != 2)
      p.push_back(at + "excitation.kind = base translation: the modal model has no base participation");
    if (!(transient_periods >= 0 && transient_periods <= dem::limits::kMaxPeriods))
      p.push_back(at + "transient_periods = " + std::to_string(transient_periods) + ": must be in [0, 100000]");
    if (!(analysed_periods >= 1 && analysed_periods <= dem::limits::kMaxPeriods))
      p.push_back(at + "analysed_periods = " + std::to_string(analysed_periods) + ": must be in [1, 100000]");
    if (!(min_transient_periods >= 0 && min_transient_periods <= std::max(transient_periods, 0)))
      p.push_back(at + "min_transient_periods = " + std::to_string(min_transient_periods) + ": must be in [0, transient_periods = " +
                  std::to_string(transient_periods) + "]");
    if (settle_until_stable && !(stable_tolerance > 0.0 && stable_tolerance < 1.0))
      p.push_back(at + "stable_tolerance = " + format_number(stable_tolerance, 12) + ": must be in (0, 1)");
    if (sweep_end_frequency_hz != 0.0) {
      if (!(sweep_end_frequency_hz >= dem::limits::kMinFrequency_hz &&
            sweep_end_frequency_hz <= dem::limits::kMaxFrequency_hz))
        p.push_back(at + "sweep_end_frequency_hz = " + format_number(sweep_end_frequency_hz, 12) +
                    ": must be 0 (one frequency) or in [0.01, 10000] Hz (a linear sweep)");
      if (!(duration_s > 0.0 && std::isfinite(duration_s)))
        p.push_back(at + "duration_s = " + format_number(duration_s, 12) +
                    ": must be > 0 and finite for a linear sweep");
    }
  } else {
    if (!(duration_s > 0.0 && std::isfinite(duration_s)))
      p.push_back(at + "duration_s = " + format_number(duration_s, 12) + ": must be > 0 and finite for a free decay");
    if (sweep_end_frequency_hz != 0.0)
      p.push_back(at + "sweep_end_frequency_hz = " + format_number(sweep_end_frequency_hz, 12) +
                  ": must be 0 for a free decay");
  }
  const auto check_initial = [&](const Eigen::VectorXd& v, const std::string& name) {
    if (v.size() != 0 && v.size() != modes)
      p.push_back(at + name + ": has " + std::to_string(v.size()) + " entries, must be empty or one per mode (" +
                  std::to_string(modes) + ")");
    else if (!v.allFinite())
      p.push_back(at + name + ": must be finite");
  };
  check_initial(initial_modal_displacements, "initial_modal_displacements");
  check_initial(initial_modal_velocities, "initial_modal_velocities");
  if (!harmonic(e) && !(initial_modal_displacements.size() && initial_modal_displacements.cwiseAbs().maxCoeff() > 0) &&
      !(initial_modal_velocities.size() && initial_modal_velocities.cwiseAbs().maxCoeff() > 0))
    p.push_back(at + "initial_modal_displacements, initial_modal_velocities: a free decay needs a non-zero start");
  if (!(bed_settling_time_s == -1.0 || (bed_settling_time_s >= 0.0 && bed_settling_time_s <= 100.0)))
    p.push_back(at + "bed_settling_time_s = " + format_number(bed_settling_time_s, 12) +
                ": must be -1 (automatic) or in [0, 100] s");
  if (forced_start_periods < 0 || forced_start_periods > 10000)
    p.push_back(at + "forced_start_periods = " + std::to_string(forced_start_periods) + ": must be in [0, 10000]");
  if (forced_start_periods > 0) {
    if (!(forced_start_frequency_hz > 0.0 && std::isfinite(forced_start_frequency_hz)))
      p.push_back(at + "forced_start_frequency_hz = " + format_number(forced_start_frequency_hz, 12) +
                  ": must be > 0 and finite with forced_start_periods");
    if (!(forced_start_peak_factor >= 1.0 && forced_start_peak_factor <= 10.0))
      p.push_back(at + "forced_start_peak_factor = " + format_number(forced_start_peak_factor, 12) + ": must be in [1, 10]");
    if (harmonic(e))
      p.push_back(at + "forced_start_periods = " + std::to_string(forced_start_periods) +
                  ": a forced start is for a free decay (the harmonic runs have their own transient)");
    if (initial_modal_velocities.size() && initial_modal_velocities.cwiseAbs().maxCoeff() > 0)
      p.push_back(at + "forced_start_periods = " + std::to_string(forced_start_periods) +
                  ": a forced start ends at rest, so the start must be at rest (initial_modal_velocities zero)");
  }
  if (!(sample_interval_s >= 0.0 && std::isfinite(sample_interval_s)))
    p.push_back(at + "sample_interval_s = " + format_number(sample_interval_s, 12) +
                ": must be >= 0 and finite (0 = automatic)");
  if (!(peak_site_speed_m_s >= 0.0 && peak_site_speed_m_s <= dem::limits::kMaxImpactSpeed_m_s))
    p.push_back(at + "peak_site_speed_m_s = " + format_number(peak_site_speed_m_s, 12) +
                ": must be in [0, 1000] m/s (0 = automatic)");
  if (!(time_step_s == 0.0 ||
        (time_step_s >= dem::limits::kMinTimeStep_s && time_step_s <= dem::limits::kMaxTimeStep_s)))
    p.push_back(at + "time_step_s = " + format_number(time_step_s, 12) +
                ": must be 0 (automatic) or in [1e-10, 1e-3] s");
  if (!(progress_interval_s > 0.0 && std::isfinite(progress_interval_s)))
    p.push_back(at + "progress_interval_s = " + format_number(progress_interval_s, 12) + ": must be > 0 and finite");
  if (snapshots < 0 || snapshots > dem::limits::kMaxSnapshots)
    p.push_back(at + "snapshots = " + std::to_string(snapshots) + ": must be in [0, " +
                std::to_string(dem::limits::kMaxSnapshots) + "]");
  return p;
}


/// Every violation of the inputs, one per line (a continuation drops the free decay's
/// need of a non-zero start: it starts from the state).
void validate_inputs(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                     const RunOptions& options, bool continuation) {
  std::vector<std::string> problems = model.validate();
  if (dampers.empty()) problems.push_back("dampers: must hold at least one damper");
  for (std::size_t d = 0; d < dampers.size(); ++d)
    for (auto& line : dampers[d].validate(model)) problems.push_back("dampers[" + std::to_string(d) + "]." + line);
  for (auto& line : options.validate(model))
    if (!(continuation && line.find("a free decay needs a non-zero start") != std::string::npos))
      problems.push_back(std::move(line));
  if (!std::isfinite(options.excitation_phase_rad))
    problems.push_back("cosimulation.excitation_phase_rad = " + format_number(options.excitation_phase_rad, 12) +
                       ": must be finite");
  if (!problems.empty()) throw std::invalid_argument(join(problems));
}

/// Whether `state` can be continued with these inputs: one line per misfit.
void validate_state(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                    const RunOptions& options, const CosimulationState& state) {
  std::vector<std::string> p;
  const std::string at = "cosimulation state: ";
  if (state.worlds.size() != dampers.size())
    p.push_back(at + "holds " + std::to_string(state.worlds.size()) + " world(s) for " + std::to_string(dampers.size()) +
                " damper(s): continue a state with the dampers that made it");
  for (std::size_t d = 0; d < state.worlds.size(); ++d)
    if (state.worlds[d].status().outcome != dem::Outcome::kCompleted)
      p.push_back(at + "world " + std::to_string(d) + " stopped (" + state.worlds[d].status().message +
                  "): it cannot be continued");
  if (state.modal_displacements.size() != model.mode_count() || state.modal_velocities.size() != model.mode_count())
    p.push_back(at + "modal state has " + std::to_string(state.modal_displacements.size()) + " entries, the model " +
                std::to_string(model.mode_count()) + " modes");
  if (!(state.time_step_s > 0.0))
    p.push_back(at + "time_step_s = " + format_number(state.time_step_s, 12) + ": must be > 0");
  if (options.initial_modal_displacements.size() || options.initial_modal_velocities.size())
    p.push_back("cosimulation.initial_modal_displacements, initial_modal_velocities: must be empty when continuing a "
                "state (the run starts from the state's q, dq/dt)");
  if (options.time_step_s != 0.0 && std::abs(options.time_step_s - state.time_step_s) > 1e-12 * state.time_step_s)
    p.push_back("cosimulation.time_step_s = " + format_number(options.time_step_s, 12) +
                ": must be 0 or the state's step " + format_number(state.time_step_s, 12) +
                " s when continuing (the worlds keep their step)");
  const auto& a = state.excitation;
  const auto& b = options.excitation;
  if (a.kind != b.kind) {
    p.push_back("cosimulation.excitation.kind: must be the state's when continuing (a harmonic run continues a "
                "harmonic run of the same load, a free decay a free decay)");
  } else if (harmonic(b)) {
    if ((a.direction - b.direction).norm() > 1e-12)
      p.push_back("cosimulation.excitation.direction = " + vec2(b.direction) + ": must be the state's " +
                  vec2(a.direction) + " when continuing");
    if (std::abs(a.amplitude - b.amplitude) > 1e-12 * std::abs(a.amplitude))
      p.push_back("cosimulation.excitation.amplitude = " + format_number(b.amplitude, 12) + ": must be the state's " +
                  format_number(a.amplitude, 12) + " when continuing (only the frequency may change)");
    if (a.point != b.point)
      p.push_back("cosimulation.excitation.point = \"" + b.point + "\": must be the state's \"" + a.point +
                  "\" when continuing");
  }
  if (!p.empty()) throw std::invalid_argument(join(p));
}

/// Modal arrays, excitation shapes and peak speeds for the start q, v at frequency f_hz.
Prepared prepare(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                 const RunOptions& options, double f_hz, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  Prepared P;
  const auto& exc = options.excitation;
  const bool is_harmonic = harmonic(exc);
  const bool is_base = exc.kind == CosimulationExcitationKind::kBaseTranslation;
  const Eigen::Index n = model.mode_count();
  const std::size_t dcount = dampers.size();

  // --- Modal arrays with the empty containers (damper_coupling's exact point masses).
  std::vector<Damper> points;
  for (const auto& d : dampers) {
    Damper p;
    p.name = d.name;
    p.point = d.point;
    p.drive_direction = d.drive_direction;
    p.container_mass_kg = d.container_mass_kg;
    p.container_rotary_inertia_kg_m2 = d.container_rotary_inertia_kg_m2;
    points.push_back(p);
  }
  P.coupled = couple(model, points);
  P.M = P.coupled.mass_with_containers_kg;
  P.w = P.coupled.angular_frequencies_rad_s;
  P.K = model.modal_masses_kg.cwiseProduct(P.w.cwiseAbs2());
  P.C = 2.0 * model.modal_masses_kg.cwiseProduct(model.damping_ratios).cwiseProduct(P.w);
  P.B = P.coupled.drive_shapes;  // modes x dampers
  P.T = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(dcount));
  for (std::size_t d = 0; d < dcount; ++d) {
    const Eigen::Vector2d across(-dampers[d].drive_direction[1], dampers[d].drive_direction[0]);  // z × n
    P.T.col(static_cast<Eigen::Index>(d)) = model.point(dampers[d].point).translation.transpose() * across;
  }
  P.R = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(dcount));  // rotation shapes
  for (std::size_t d = 0; d < dcount; ++d) {
    const Eigen::RowVectorXd& rot = model.point(dampers[d].point).rotation;
    if (dampers[d].rotation) {
      P.R.col(static_cast<Eigen::Index>(d)) = rot.transpose();
    } else if (rot.cwiseAbs().maxCoeff() > 0.0) {
      P.warnings.push_back("damper " + dampers[d].name +
                           ": the site rotates (max |θ_j| = " + format_number(rot.cwiseAbs().maxCoeff(), 12) +
                           " rad per unit q) but rotation = false: the container only translates");
    }
  }
  P.M_inv = P.M.inverse();

  // Excitation: f_exc(t) = load_shape · (drive factor).
  P.omega = is_harmonic ? kTwoPi * f_hz : 0.0;
  P.load_shape = Eigen::VectorXd::Zero(n);
  P.base_shape = Eigen::VectorXd::Zero(n);   // P_e = (Γ + Σ m_c Φ_dᵀ) e
  P.drive_dot_e.assign(dcount, 0.0);         // n_d · e (base motion of the sites)
  P.across_dot_e.assign(dcount, 0.0);        // t_d · e
  P.force_shape = Eigen::VectorXd::Zero(n);  // Φ_pᵀ e
  if (exc.kind == CosimulationExcitationKind::kPointForce) {
    P.force_shape = model.point(exc.point).translation.transpose() * exc.direction;
    P.load_shape = exc.amplitude * P.force_shape;
  } else if (is_base) {
    P.base_shape = (P.coupled.base_participation + P.coupled.container_participation) * exc.direction;
    P.load_shape = exc.amplitude * P.base_shape;  // −P_e ü_b
    for (std::size_t d = 0; d < dcount; ++d) {
      P.drive_dot_e[d] = dampers[d].drive_direction.dot(exc.direction);
      P.across_dot_e[d] = -dampers[d].drive_direction[1] * exc.direction[0] + dampers[d].drive_direction[0] * exc.direction[1];
    }
  }
  P.U = is_base ? exc.amplitude : 0.0;

  // --- Peak site speed for the time-step rule.
  P.peak_speed.assign(dcount, options.peak_site_speed_m_s);
  if (options.peak_site_speed_m_s == 0.0) {
    const double e0 = 0.5 * v.dot(P.M * v) + 0.5 * q.dot(P.K.cwiseProduct(q));
    for (std::size_t d = 0; d < dcount; ++d) {
      const auto col = static_cast<Eigen::Index>(d);
      // Free motion: |b·q̇| <= √(2E bᵀM⁻¹b) (Cauchy-Schwarz in the M norm).
      P.peak_speed[d] = std::sqrt(2.0 * e0 * P.B.col(col).dot(P.M_inv * P.B.col(col)));
    }
    if (is_harmonic) {
      // The linear steady state at the frequency, or its largest over a sweep's band (a
      // fine grid and the natural frequencies inside it).
      std::vector<double> frequencies{f_hz};
      if (sweeping(options)) {
        const double lo = std::min(exc.frequency_hz, options.sweep_end_frequency_hz);
        const double hi = std::max(exc.frequency_hz, options.sweep_end_frequency_hz);
        constexpr int kGrid = 256;
        frequencies.clear();
        for (int k = 0; k <= kGrid; ++k) frequencies.push_back(lo + (hi - lo) * k / kGrid);
        for (const double w : P.w)
          if (w / kTwoPi > lo && w / kTwoPi < hi) frequencies.push_back(w / kTwoPi);
      }
      std::vector<double> linear_speed(dcount, 0.0);
      Eigen::MatrixXcd D;
      for (const double f : frequencies) {
        const double omega = kTwoPi * f;
        linear_dynamic_stiffness(P.coupled, omega, D);
        const Eigen::VectorXd load = is_base ? Eigen::VectorXd(omega * omega * P.load_shape) : P.load_shape;
        const Eigen::VectorXcd qhat = D.partialPivLu().solve(load.cast<std::complex<double>>());
        for (std::size_t d = 0; d < dcount; ++d) {
          const auto col = static_cast<Eigen::Index>(d);
          const std::complex<double> y = P.B.col(col).cast<std::complex<double>>().dot(qhat) + P.drive_dot_e[d] * P.U;
          linear_speed[d] = std::max(linear_speed[d], std::abs(y) * omega);
        }
      }
      // Twice the linear steady state (the start transient can overshoot it), plus the start.
      for (std::size_t d = 0; d < dcount; ++d) P.peak_speed[d] += 2.0 * linear_speed[d];
    }
    for (auto& s : P.peak_speed) s = std::min(s, 0.5 * dem::limits::kMaxImpactSpeed_m_s);
  }
  return P;
}

StepPlan plan_step(const Prepared& P, const std::vector<CosimulationDamper>& dampers, const RunOptions& options,
                   double f_hz) {
  StepPlan plan;
  const bool is_harmonic = harmonic(options.excitation);
  const std::size_t dcount = dampers.size();
  const double omega_max = P.w.maxCoeff();
  double& dt = plan.dt;
  std::int64_t& steps_per_period = plan.steps_per_period;
  if (is_harmonic) {
    const double period = 1.0 / f_hz;
    for (std::size_t d = 0; d < dcount; ++d) {
      dem::WorldOptions wo = dampers[d].world;
      if (options.time_step_s > 0.0) wo.integration.time_step_s = options.time_step_s;
      const dem::DriveTimeStep drive = dem::drive_time_step(
          wo, dem::DriveTiming{period, 1, dem::drive_impact_speed(wo, P.peak_speed[d])});
      for (const auto& wline : drive.warnings) plan.warnings.push_back("damper " + dampers[d].name + ": " + wline);
      steps_per_period = std::max(steps_per_period, drive.steps_per_period);
      plan.world_options.push_back(drive.world);
    }
    if (options.time_step_s == 0.0)
      steps_per_period = std::max(
          steps_per_period, static_cast<std::int64_t>(std::ceil(omega_max * period / kStructureStepTarget)));
    dt = period / static_cast<double>(steps_per_period);
  } else {
    dt = dem::limits::kMaxTimeStep_s;
    for (std::size_t d = 0; d < dcount; ++d) {
      dem::WorldOptions wo = dampers[d].world;
      wo.integration.max_impact_speed_m_s =
          std::max(wo.integration.max_impact_speed_m_s, dem::drive_impact_speed(wo, P.peak_speed[d]));
      wo.integration.time_step_s = 0.0;
      dt = std::min(dt, dem::time_step_bound(wo).max_time_step_s);
      plan.world_options.push_back(wo);
    }
    if (options.time_step_s > 0.0) {
      if (options.time_step_s > dt)
        throw std::invalid_argument("cosimulation.time_step_s = " + format_number(options.time_step_s, 12) +
                                    ": must be <= the worlds' automatic bound " + format_number(dt, 12) + " s");
      dt = options.time_step_s;
    } else {
      dt = std::min(dt, kStructureStepTarget / omega_max);
    }
  }
  if (omega_max * dt > kStructureStepLimit)
    throw std::invalid_argument("cosimulation.time_step_s = " + format_number(dt, 12) + ": the highest mode (" +
                                format_number(omega_max / kTwoPi, 12) +
                                " Hz) needs ω·dt <= 0.2 for the modal Verlet step");
  return plan;
}

/// |W − (D_s + D_dem + ΔE_s + ΔE_bed)| / max(|W|, D_s + D_dem, |ΔE_s|) (CosimulationEnergy).
double ledger_error(const CosimulationEnergy& e) {
  const double dissipated = e.structural_damping_j + e.dem_dissipated_j();
  const double delta = e.delta_structure_kinetic_j + e.delta_structure_potential_j + e.delta_bed_kinetic_j +
                       e.delta_bed_potential_j + e.delta_bed_elastic_j;
  const double scale = std::max({std::abs(e.excitation_work_j), dissipated,
                                 std::abs(e.delta_structure_kinetic_j + e.delta_structure_potential_j)});
  return scale > 0.0 ? std::abs(e.excitation_work_j - dissipated - delta) / scale : 0.0;
}

/// The energy terms of CosimulationEnergy in one order (sums and checkpoints).
std::array<double*, 11> energy_terms(CosimulationEnergy& e) {
  return {&e.excitation_work_j, &e.structural_damping_j, &e.delta_structure_kinetic_j, &e.delta_structure_potential_j,
          &e.dem_normal_damping_j, &e.dem_friction_j, &e.dem_rolling_j, &e.delta_bed_kinetic_j,
          &e.delta_bed_potential_j, &e.delta_bed_elastic_j, &e.container_work_j};
}

Eigen::VectorXd start_vector(const Eigen::VectorXd& given, Eigen::Index n) {
  return given.size() ? given : Eigen::VectorXd::Zero(n);
}

}  // namespace detail

}  // namespace pdamp::structure
