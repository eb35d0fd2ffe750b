// First-order harmonic balance of a modal model with particle dampers: the amplitude
// equations, their roots, slow-flow stability, branches, folds, jumps and peaks.
//
// Method (docs/structure_coupling.md §3-5; Krack & Gross, "Harmonic Balance for Nonlinear
// Vibration Problems", Springer 2019, ch. 2-3 for the first-harmonic ansatz and the
// slow-flow stability; NLvib for the same single-harmonic treatment of amplitude-dependent
// elements). Per frequency the structure with the empty containers is linear: one LU of the
// modal dynamic stiffness gives the damper sites' linear response y_lin and their mutual
// receptance G. The beds' forces −Z_d(X_d)·y_d close the loop:
//   (I + G·diag Z(X)) y = y_lin,   X_d = |y_d|,
// a D-dimensional problem whatever the number of modes.
#include "pdamp/structure/harmonic_balance.hpp"

#include "pdamp/base/one_dimensional.hpp"
#include "pdamp/structure/sampled_response.hpp"
#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pdamp::structure {

namespace {

using Complex = std::complex<double>;
using detail::kTwoPi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// The side of a jump a piece ends on: the stroke one part in 10¹² inside the piece, far
/// above round-off of the loss model's classification and far below any tolerance.
constexpr double kInsidePiece = 1e-12;
/// Slow-flow eigenvalues with |Re λ| below this fraction of Ω count as zero (at a fold the
/// eigenvalue crosses 0; round-off of the 2N x 2N eigenproblem is ~1e-14 Ω).
constexpr double kMarginalGrowth = 1e-9;
/// Golden-section and frequency bisection steps of the branch-end search: 2⁻⁶⁰ of the grid
/// step in frequency, 0.618⁶⁰ ≈ 3e-13 of the bracket in ln X.
constexpr int kRefineIterations = 60;

const PointModeShape& point_of(const ModalModel& model, const std::string& name) {
  for (const auto& p : model.points)
    if (p.name == name) return p;
  throw std::invalid_argument("harmonic_balance: point \"" + name + "\" is not a point of the modal model");
}

using base::format_number;

/// The linear structure with empty containers at one frequency, and the loop closure.
class FrequencyOperator {
 public:
  FrequencyOperator(const CoupledModel& coupled, const ModalModel& model, const Excitation& excitation,
                    const std::vector<ResponseOutput>& outputs)
      : coupled_(coupled), excitation_(excitation) {
    const Eigen::Index modes = coupled.angular_frequencies_rad_s.size();
    const Eigen::Index dampers = coupled.drive_shapes.cols();
    const Eigen::Index out_count = static_cast<Eigen::Index>(outputs.size());
    output_rows_.resize(out_count, modes);
    output_base_.resize(out_count);
    for (Eigen::Index o = 0; o < out_count; ++o) {
      const auto& shape = point_of(model, outputs[static_cast<std::size_t>(o)].point).translation;
      const Eigen::Vector2d& e = outputs[static_cast<std::size_t>(o)].direction;
      output_rows_.row(o) = e.transpose() * shape;
      output_base_[o] = excitation.kind == Excitation::Kind::kBaseTranslation ? e.dot(excitation.direction) : 0.0;
    }
    if (excitation.kind == Excitation::Kind::kBaseTranslation) {
      // Modal load of a base displacement û_b = U e: Ω²(Γ + Σ m_c Φ_dᵀ) e U (the containers
      // are accelerated with the base too), and the sites' base motion w_d = n_d·e U.
      base_load_ = (coupled.base_participation + coupled.container_participation) * excitation.direction;
      site_base_.resize(dampers);
      for (Eigen::Index d = 0; d < dampers; ++d)
        site_base_[d] = coupled.dampers[static_cast<std::size_t>(d)].drive_direction.dot(excitation.direction);
    } else {
      base_load_ = point_of(model, excitation.point).translation.transpose() * excitation.direction;
      site_base_ = Eigen::VectorXd::Zero(dampers);
    }
    damping_matrix_ = Eigen::VectorXd(2.0 * coupled.damping_ratios.array() * coupled.angular_frequencies_rad_s.array() *
                                      coupled.modal_masses_kg.array())
                          .asDiagonal();
    dynamic_stiffness_.resize(modes, modes);
    lu_ = Eigen::PartialPivLU<Eigen::MatrixXcd>(modes);
    slow_lu_ = Eigen::PartialPivLU<Eigen::MatrixXcd>(modes);
    impedances_.resize(static_cast<std::size_t>(dampers));
    jacobian_.resize(2 * modes, 2 * modes);
    eigen_ = Eigen::EigenSolver<Eigen::MatrixXd>(2 * modes);
  }

  void set_frequency(double frequency_hz) {
    frequency_hz_ = frequency_hz;
    omega_ = kTwoPi * frequency_hz;
    linear_dynamic_stiffness(coupled_, omega_, dynamic_stiffness_);
    lu_.compute(dynamic_stiffness_);
    const double amplitude = excitation_.amplitude;
    const double load_scale = excitation_.kind == Excitation::Kind::kBaseTranslation ? omega_ * omega_ * amplitude
                                                                                     : amplitude;
    linear_modal_ = lu_.solve((load_scale * base_load_).cast<Complex>());
    site_solve_ = lu_.solve(coupled_.drive_shapes.cast<Complex>());              // S = D⁻¹B
    receptance_ = coupled_.drive_shapes.transpose().cast<Complex>() * site_solve_;  // G = BᵀD⁻¹B
    site_linear_ = coupled_.drive_shapes.transpose().cast<Complex>() * linear_modal_ +
                   (amplitude * site_base_).cast<Complex>();
    output_linear_ = output_rows_.cast<Complex>() * linear_modal_ + (amplitude * output_base_).cast<Complex>();
    output_per_force_ = output_rows_.cast<Complex>() * site_solve_;
    // Slow flow (2iΩ M + C) ȧ = −R(a): its matrix is factored once per frequency.
    slow_lu_.compute(Complex(0.0, 2.0 * omega_) * coupled_.mass_with_containers_kg.cast<Complex>() +
                     damping_matrix_.cast<Complex>());
    slow_inverse_ = slow_lu_.inverse();
  }

  double frequency_hz() const { return frequency_hz_; }
  Eigen::Index damper_count() const { return coupled_.drive_shapes.cols(); }
  const Eigen::VectorXcd& output_linear() const { return output_linear_; }
  const Eigen::VectorXcd& site_linear() const { return site_linear_; }

  /// One damper: the site response y(X) = y_lin/(1 + G Z(X)).
  Complex single_site_response(double stroke_m) {
    ++evaluations_;
    impedances_[0] = damper_impedance(coupled_.dampers[0], frequency_hz_, stroke_m, coupled_.options);
    return site_linear_[0] / (1.0 + receptance_(0, 0) * impedances_[0].dynamic_stiffness_n_m);
  }
  /// Residual of the amplitude equation in relative form, |y(X)|/X − 1 (same sign as
  /// |y| − X, scale-free for the tolerance).
  double single_residual(double stroke_m) { return std::abs(single_site_response(stroke_m)) / stroke_m - 1.0; }

  /// One damper held at a jump X_j: the λ in (0, 1) with |y_lin/(1 + G Z_λ)| = X_j,
  /// Z_λ = (1 − λ)Z(X_j⁻) + λZ(X_j⁺), by bisection (60 steps: λ to 1e-18); fills the state.
  void hold_at_jump(double below_m, double jump_m, JumpHeldState& state) {
    const Complex z_below = damper_impedance(coupled_.dampers[0], frequency_hz_, below_m, coupled_.options).dynamic_stiffness_n_m;
    const Complex z_above = damper_impedance(coupled_.dampers[0], frequency_hz_, jump_m, coupled_.options).dynamic_stiffness_n_m;
    evaluations_ += 2;
    auto site = [&](double lambda) {
      return site_linear_[0] / (1.0 + receptance_(0, 0) * ((1.0 - lambda) * z_below + lambda * z_above));
    };
    double lo = 0.0, hi = 1.0;  // |y| > X at lo, < X at hi
    for (int iteration = 0; iteration < kRefineIterations; ++iteration) {
      const double mid = 0.5 * (lo + hi);
      (std::abs(site(mid)) > jump_m ? lo : hi) = mid;
    }
    const double lambda = 0.5 * (lo + hi);
    const Complex z = (1.0 - lambda) * z_below + lambda * z_above;
    const Complex force = z * site(lambda);
    state.damper_amplitude_m = jump_m;
    state.upper_state_fraction = lambda;
    state.outputs.resize(static_cast<std::size_t>(output_linear_.size()));
    for (Eigen::Index o = 0; o < output_linear_.size(); ++o)
      state.outputs[static_cast<std::size_t>(o)] = (output_linear_[o] - output_per_force_(o, 0) * force) / excitation_.amplitude;
  }

  /// Several dampers: y solving (I + G diag Z(X)) y = y_lin; fills impedances_.
  Eigen::VectorXcd site_response(const Eigen::VectorXd& strokes_m) {
    const Eigen::Index dampers = damper_count();
    Eigen::MatrixXcd closure = Eigen::MatrixXcd::Identity(dampers, dampers);
    for (Eigen::Index d = 0; d < dampers; ++d) {
      ++evaluations_;
      impedances_[static_cast<std::size_t>(d)] =
          damper_impedance(coupled_.dampers[static_cast<std::size_t>(d)], frequency_hz_, strokes_m[d], coupled_.options);
      closure.col(d) += receptance_.col(d) * impedances_[static_cast<std::size_t>(d)].dynamic_stiffness_n_m;
    }
    return closure.partialPivLu().solve(site_linear_);
  }

  /// Outputs, stability and η* of a root whose site responses are y (impedances_ current).
  void describe_root(const Eigen::VectorXcd& sites, HarmonicRoot& root) {
    const Eigen::Index dampers = damper_count();
    const Eigen::Index modes = dynamic_stiffness_.rows();
    Eigen::VectorXcd forces(dampers);
    root.loss_warnings = 0;
    for (Eigen::Index d = 0; d < dampers; ++d) {
      forces[d] = impedances_[static_cast<std::size_t>(d)].dynamic_stiffness_n_m * sites[d];
      root.loss_warnings |= impedances_[static_cast<std::size_t>(d)].loss_warnings;
    }
    root.outputs.resize(static_cast<std::size_t>(output_linear_.size()));
    const Eigen::VectorXcd outputs = output_linear_ - output_per_force_ * forces;
    for (Eigen::Index o = 0; o < outputs.size(); ++o)
      root.outputs[static_cast<std::size_t>(o)] = outputs[o] / excitation_.amplitude;
    root.layer_eta_star.clear();
    for (Eigen::Index d = 0; d < dampers; ++d)
      for (const auto& layer : coupled_.dampers[static_cast<std::size_t>(d)].layers)
        root.layer_eta_star.push_back(
            layer.loss_model->evaluate(frequency_hz_, root.damper_amplitudes_m[static_cast<std::size_t>(d)]).eta_star);
    // Slow flow ȧ = −(2iΩM + C)⁻¹ R(a), R(a) = D a − r + Σ_d b_d Z_d(|y_d|) y_d, y = Bᵀa + w.
    // R is not complex-analytic (|y|), so it is linearised in (Re a, Im a):
    //   ∂(Z y)/∂Re y = Z + y Z' Re y/|y|,  ∂(Z y)/∂Im y = iZ + y Z' Im y/|y|.
    Eigen::MatrixXcd d_real = dynamic_stiffness_;
    Eigen::MatrixXcd d_imag = Complex(0.0, 1.0) * dynamic_stiffness_;
    for (Eigen::Index d = 0; d < dampers; ++d) {
      const auto& z = impedances_[static_cast<std::size_t>(d)];
      const Complex y = sites[d];
      const double magnitude = std::abs(y);
      const Complex slope = y * z.d_dynamic_stiffness_d_stroke / magnitude;
      const Complex h_real = z.dynamic_stiffness_n_m + slope * y.real();
      const Complex h_imag = Complex(0.0, 1.0) * z.dynamic_stiffness_n_m + slope * y.imag();
      const Eigen::MatrixXd outer = coupled_.drive_shapes.col(d) * coupled_.drive_shapes.col(d).transpose();
      d_real += h_real * outer.cast<Complex>();
      d_imag += h_imag * outer.cast<Complex>();
    }
    const Eigen::MatrixXcd a_real = -slow_inverse_ * d_real;
    const Eigen::MatrixXcd a_imag = -slow_inverse_ * d_imag;
    jacobian_.topLeftCorner(modes, modes) = a_real.real();
    jacobian_.topRightCorner(modes, modes) = a_imag.real();
    jacobian_.bottomLeftCorner(modes, modes) = a_real.imag();
    jacobian_.bottomRightCorner(modes, modes) = a_imag.imag();
    eigen_.compute(jacobian_, false);
    root.max_growth_rate_1_s = eigen_.eigenvalues().real().maxCoeff();
    const double marginal = kMarginalGrowth * omega_;
    root.stability = root.max_growth_rate_1_s > marginal    ? Stability::kUnstable
                     : root.max_growth_rate_1_s < -marginal ? Stability::kStable
                                                            : Stability::kMarginal;
  }

  std::size_t evaluations() const { return evaluations_; }

 private:
  const CoupledModel& coupled_;
  const Excitation& excitation_;
  double frequency_hz_ = 0.0;
  double omega_ = 0.0;
  Eigen::MatrixXd output_rows_;     ///< outputs x modes: e_oᵀΦ_o
  Eigen::VectorXd output_base_;     ///< e_o·e for base excitation (absolute outputs), else 0
  Eigen::VectorXd base_load_;       ///< modal load per unit excitation (before Ω² U or F)
  Eigen::VectorXd site_base_;       ///< n_d·e (base excitation)
  Eigen::MatrixXd damping_matrix_;  ///< diag(2 ζ_j ω_j m_j)
  Eigen::MatrixXcd dynamic_stiffness_;
  Eigen::PartialPivLU<Eigen::MatrixXcd> lu_;
  Eigen::PartialPivLU<Eigen::MatrixXcd> slow_lu_;
  Eigen::MatrixXcd slow_inverse_;
  Eigen::VectorXcd linear_modal_;
  Eigen::MatrixXcd site_solve_;
  Eigen::MatrixXcd receptance_;
  Eigen::VectorXcd site_linear_;
  Eigen::VectorXcd output_linear_;
  Eigen::MatrixXcd output_per_force_;
  std::vector<DamperImpedance> impedances_;
  Eigen::MatrixXd jacobian_;
  Eigen::EigenSolver<Eigen::MatrixXd> eigen_;
  std::size_t evaluations_ = 0;
};

/// Root of a continuous residual with f(lo) and f(hi) of opposite signs, in ln X: the
/// Illinois regula falsi (base::IllinoisBracket) with a bisection step where the secant
/// leaves the bracket; stops at a bracket narrower than the relative tolerance.
template <class Residual>
double illinois_log_root(Residual&& residual, double lo, double f_lo, double hi, double f_hi, double tolerance) {
  base::IllinoisBracket bracket{std::log(lo), f_lo, std::log(hi), f_hi};
  for (int iteration = 0; iteration < 200 && bracket.hi - bracket.lo > tolerance; ++iteration) {
    double x = bracket.secant();
    if (!(x > bracket.lo && x < bracket.hi)) x = 0.5 * (bracket.lo + bracket.hi);
    const double f = residual(std::exp(x));
    if (f == 0.0) return std::exp(x);
    bracket.update(x, f);
  }
  return std::exp(0.5 * (bracket.lo + bracket.hi));
}

/// A smooth piece of the stroke axis: [lo, hi] with the pieces' indices counted from the
/// lowest jump.
struct Piece {
  double lo_m, hi_m;
  int index;
};

/// The pieces of [x_min, x_max] between the damper's jumps at f.
void pieces_at(const Damper& damper, double frequency_hz, double x_min, double x_max, std::vector<Piece>& pieces) {
  pieces.clear();
  const auto jumps = damper_discontinuities_m(damper, frequency_hz);
  double lo = x_min;
  int index = 0;
  for (double jump : jumps) {
    if (jump <= x_min) {
      ++index;
      continue;
    }
    if (jump >= x_max) break;
    pieces.push_back({lo, jump * (1.0 - kInsidePiece), index});
    lo = jump;
    ++index;
  }
  pieces.push_back({lo, x_max, index});
}

struct ScanSettings {
  double x_min, x_max;
  int points_per_decade;
  double tolerance;
};

/// Golden-section search (base::golden_section) for the maximum of sign·residual on
/// [lo, hi] in ln X, kRefineIterations steps (0.618⁶⁰ ≈ 3e-13 of the bracket); returns the
/// value and its abscissa.
template <class Residual>
double golden_maximum(Residual&& residual, double lo, double hi, double sign, double& at) {
  base::GoldenSectionOptions search;
  search.maximum = true;
  search.max_iterations = kRefineIterations;
  const base::GoldenSection s =
      base::golden_section([&](double u) { return sign * residual(std::exp(u)); }, std::log(lo), std::log(hi), search);
  at = std::exp(s.middle());
  return std::max(s.f1, s.f2);
}

/// Scan workspace, reused across frequencies (no allocation once grown).
struct ScanWorkspace {
  std::vector<Piece> pieces;
  std::vector<double> x, f, roots;
};

/// Every root of the relative residual on every piece: sign changes between scan nodes,
/// and pairs hidden inside one cell (a node where |g| has a local minimum without a sign
/// change: the extremum is searched and, if it crosses 0, both roots are refined), so two
/// roots closer than a cell are found next to their fold too. One damper.
void single_damper_roots(FrequencyOperator& op, const Damper& damper, const ScanSettings& scan, ScanWorkspace& work,
                         FrequencyPoint& point) {
  std::vector<HarmonicRoot>& roots = point.roots;
  roots.clear();
  point.held_at_jump.clear();
  pieces_at(damper, op.frequency_hz(), scan.x_min, scan.x_max, work.pieces);
  auto residual = [&](double x) { return op.single_residual(x); };
  double residual_below_jump = 0.0;  // the previous piece's residual at its upper end
  for (std::size_t p = 0; p < work.pieces.size(); ++p) {
    const Piece& piece = work.pieces[p];
    const double decades = std::log10(piece.hi_m / piece.lo_m);
    const int cells = std::max(2, static_cast<int>(std::ceil(decades * scan.points_per_decade)));
    work.x.resize(static_cast<std::size_t>(cells) + 1);
    work.f.resize(work.x.size());
    for (int k = 0; k <= cells; ++k) {
      const double x = k == cells ? piece.hi_m : piece.lo_m * std::pow(piece.hi_m / piece.lo_m, double(k) / cells);
      work.x[static_cast<std::size_t>(k)] = x;
      work.f[static_cast<std::size_t>(k)] = residual(x);
    }
    work.roots.clear();
    const auto& xs = work.x;
    const auto& fs = work.f;
    if (p > 0 && residual_below_jump > 0.0 && fs.front() < 0.0) {
      point.held_at_jump.emplace_back();
      op.hold_at_jump(work.pieces[p - 1].hi_m, piece.lo_m, point.held_at_jump.back());
    }
    residual_below_jump = fs.back();
    for (std::size_t k = 0; k + 1 < xs.size(); ++k) {
      if (fs[k] == 0.0) {
        work.roots.push_back(xs[k]);
      } else if (fs[k + 1] != 0.0 && (fs[k] > 0.0) != (fs[k + 1] > 0.0)) {
        work.roots.push_back(illinois_log_root(residual, xs[k], fs[k], xs[k + 1], fs[k + 1], scan.tolerance));
      } else if (k > 0 && fs[k] != 0.0 && (fs[k - 1] > 0.0) == (fs[k] > 0.0) && (fs[k + 1] > 0.0) == (fs[k] > 0.0) &&
                 std::abs(fs[k]) < std::abs(fs[k - 1]) && std::abs(fs[k]) < std::abs(fs[k + 1])) {
        const double sign = fs[k] > 0.0 ? -1.0 : 1.0;  // toward zero
        double at = 0.0;
        if (golden_maximum(residual, xs[k - 1], xs[k + 1], sign, at) > 0.0) {
          const double f_at = residual(at);
          // Both roots, left then right of the extremum; drop a left one the previous cell found.
          const double left = illinois_log_root(residual, xs[k - 1], fs[k - 1], at, f_at, scan.tolerance);
          if (work.roots.empty() || std::abs(std::log(left / work.roots.back())) > 10.0 * scan.tolerance)
            work.roots.push_back(left);
          work.roots.push_back(illinois_log_root(residual, at, f_at, xs[k + 1], fs[k + 1], scan.tolerance));
          std::sort(work.roots.end() - 2, work.roots.end());
        }
      }
    }
    if (fs.back() == 0.0) work.roots.push_back(xs.back());
    for (double root_m : work.roots) {
      HarmonicRoot root;
      root.damper_amplitudes_m = {root_m};
      root.piece = piece.index;
      Eigen::VectorXcd site(1);
      site[0] = op.single_site_response(root_m);
      op.describe_root(site, root);
      roots.push_back(std::move(root));
    }
  }
}

/// Several dampers: Newton on F(u) = ln|y(e^u)| − u (u = ln X) with a finite-difference
/// Jacobian (step 1e-7 in u: the residual is smooth to ~1e-15, so the O(h) truncation and
/// the O(ε/h) round-off balance near 1e-8) and backtracking; damped fixed point
/// u ← u + λF(u) if Newton fails.
bool newton_root(FrequencyOperator& op, const ScanSettings& scan, const HarmonicBalanceOptions& options,
                 Eigen::VectorXd& strokes_m) {
  const Eigen::Index n = strokes_m.size();
  const double lo = std::log(scan.x_min), hi = std::log(scan.x_max);
  Eigen::VectorXd u = strokes_m.array().log().max(lo).min(hi).matrix();
  auto residual = [&](const Eigen::VectorXd& v) {
    const Eigen::VectorXcd y = op.site_response(v.array().exp().matrix());
    return Eigen::VectorXd((y.array().abs().log() - v.array()).matrix());
  };
  Eigen::VectorXd f = residual(u);
  const double tolerance = std::max(scan.tolerance, 1e-13);
  for (int iteration = 0; iteration < options.max_newton_iterations && f.lpNorm<Eigen::Infinity>() > tolerance;
       ++iteration) {
    Eigen::MatrixXd jac(n, n);
    constexpr double kStep = 1e-7;
    for (Eigen::Index j = 0; j < n; ++j) {
      Eigen::VectorXd shifted = u;
      shifted[j] += kStep;
      jac.col(j) = (residual(shifted) - f) / kStep;
    }
    const Eigen::VectorXd step = jac.fullPivLu().solve(-f);
    double lambda = 1.0;
    bool improved = false;
    for (int halving = 0; halving < 30; ++halving, lambda *= 0.5) {
      const Eigen::VectorXd trial = (u + lambda * step).array().max(lo).min(hi).matrix();
      const Eigen::VectorXd f_trial = residual(trial);
      if (f_trial.allFinite() && f_trial.norm() < f.norm()) {
        u = trial;
        f = f_trial;
        improved = true;
        break;
      }
    }
    if (!improved) break;
  }
  for (int iteration = 0; iteration < 2000 && !(f.lpNorm<Eigen::Infinity>() <= tolerance); ++iteration) {
    u = (u + options.fixed_point_relaxation * f).array().max(lo).min(hi).matrix();
    f = residual(u);
  }
  strokes_m = u.array().exp().matrix();
  return f.lpNorm<Eigen::Infinity>() <= 1e3 * tolerance;
}

void multi_damper_roots(FrequencyOperator& op, const ScanSettings& scan, const HarmonicBalanceOptions& options,
                        const std::vector<HarmonicRoot>& previous, FrequencyPoint& point, std::size_t& failures) {
  const Eigen::Index dampers = op.damper_count();
  std::vector<Eigen::VectorXd> starts;
  for (const auto& root : previous)
    starts.push_back(Eigen::Map<const Eigen::VectorXd>(root.damper_amplitudes_m.data(), dampers));
  starts.push_back(op.site_linear().array().abs().max(scan.x_min).min(scan.x_max).matrix());
  constexpr int kGridStarts = 8;
  for (int k = 0; k < kGridStarts; ++k)
    starts.push_back(Eigen::VectorXd::Constant(
        dampers, scan.x_min * std::pow(scan.x_max / scan.x_min, (k + 0.5) / kGridStarts)));
  for (auto& start : starts) {
    if (!newton_root(op, scan, options, start)) {
      ++failures;
      point.converged = false;
      continue;
    }
    bool known = false;
    for (const auto& root : point.roots)
      known = known || (Eigen::Map<const Eigen::VectorXd>(root.damper_amplitudes_m.data(), dampers) - start)
                               .cwiseQuotient(start)
                               .lpNorm<Eigen::Infinity>() < 1e-6;
    if (known) continue;
    HarmonicRoot root;
    root.damper_amplitudes_m.assign(start.data(), start.data() + dampers);
    const Eigen::VectorXcd sites = op.site_response(start);
    op.describe_root(sites, root);
    point.roots.push_back(std::move(root));
  }
  std::sort(point.roots.begin(), point.roots.end(), [](const HarmonicRoot& a, const HarmonicRoot& b) {
    return a.damper_amplitudes_m[0] < b.damper_amplitudes_m[0];
  });
}

/// Links the roots of consecutive frequencies into branch segments (same piece; in order
/// where the counts agree, else mutual nearest in ln X) and records where segments end.
struct Linker {
  int next_id = 0;

  void start(std::vector<HarmonicRoot>& roots) {
    for (auto& root : roots) root.branch_id = next_id++;
  }

  /// Sets branch ids of `now` from `before`; returns the unmatched indices of both.
  void link(const std::vector<HarmonicRoot>& before, std::vector<HarmonicRoot>& now, std::vector<int>& ended,
            std::vector<int>& born) {
    ended.clear();
    born.clear();
    std::vector<int> match_now(now.size(), -1), match_before(before.size(), -1);
    int max_piece = 0;
    for (const auto& r : before) max_piece = std::max(max_piece, r.piece);
    for (const auto& r : now) max_piece = std::max(max_piece, r.piece);
    for (int piece = 0; piece <= max_piece; ++piece) {
      std::vector<int> b, n;
      for (std::size_t i = 0; i < before.size(); ++i)
        if (before[i].piece == piece) b.push_back(static_cast<int>(i));
      for (std::size_t i = 0; i < now.size(); ++i)
        if (now[i].piece == piece) n.push_back(static_cast<int>(i));
      if (b.size() == n.size()) {
        for (std::size_t k = 0; k < b.size(); ++k) {
          match_now[static_cast<std::size_t>(n[k])] = b[k];
          match_before[static_cast<std::size_t>(b[k])] = n[k];
        }
        continue;
      }
      auto distance = [&](int i, int j) {
        return std::abs(std::log(before[static_cast<std::size_t>(i)].damper_amplitudes_m[0] /
                                 now[static_cast<std::size_t>(j)].damper_amplitudes_m[0]));
      };
      for (int j : n) {
        int best = -1;
        for (int i : b)
          if (best < 0 || distance(i, j) < distance(best, j)) best = i;
        if (best < 0) continue;
        int best_back = -1;
        for (int k : n)
          if (best_back < 0 || distance(best, k) < distance(best, best_back)) best_back = k;
        if (best_back == j) {
          match_now[static_cast<std::size_t>(j)] = best;
          match_before[static_cast<std::size_t>(best)] = j;
        }
      }
    }
    for (std::size_t j = 0; j < now.size(); ++j) {
      if (match_now[j] >= 0) {
        now[j].branch_id = before[static_cast<std::size_t>(match_now[j])].branch_id;
      } else {
        now[j].branch_id = next_id++;
        born.push_back(static_cast<int>(j));
      }
    }
    for (std::size_t i = 0; i < before.size(); ++i)
      if (match_before[i] < 0) ended.push_back(static_cast<int>(i));
  }
};

/// Locates the ends of segments between two grid frequencies (one damper).
class BranchEndFinder {
 public:
  BranchEndFinder(FrequencyOperator& op, const Damper& damper, const ScanSettings& scan)
      : op_(op), damper_(damper), scan_(scan) {}

  /// Classifies the unmatched roots of `roots` (at `f_root`, the side where they exist)
  /// into folds (adjacent pairs on a piece), cliffs (next to a jump) or range ends, and
  /// refines each in [f_root, f_other] (either order).
  void classify(const std::vector<HarmonicRoot>& roots, const std::vector<int>& unmatched, double f_root,
                double f_other, bool refine, std::vector<BranchEnd>& ends) {
    std::vector<bool> used(unmatched.size(), false);
    for (std::size_t k = 0; k < unmatched.size(); ++k) {
      if (used[k]) continue;
      const auto& root = roots[static_cast<std::size_t>(unmatched[k])];
      const int index = unmatched[k];
      BranchEnd end;
      end.branch_id = root.branch_id;
      end.damper_amplitude_m = root.damper_amplitudes_m[0];
      end.ends_toward_higher_frequency = f_other > f_root;
      end.frequency_hz = 0.5 * (f_root + f_other);
      const bool pair = k + 1 < unmatched.size() && unmatched[k + 1] == index + 1 &&
                        roots[static_cast<std::size_t>(index + 1)].piece == root.piece;
      if (pair) {
        used[k + 1] = true;
        end.kind = BranchEnd::Kind::kFold;
        end.other_branch_id = roots[static_cast<std::size_t>(index + 1)].branch_id;
        if (refine) refine_fold(roots, index, f_root, f_other, end);
      } else {
        refine_single(roots, index, f_root, f_other, refine, end);
      }
      ends.push_back(end);
    }
  }

 private:
  double pair_extremum(double lo, double hi, double sign, double& at) {
    return golden_maximum([&](double x) { return op_.single_residual(x); }, lo, hi, sign, at);
  }

  void refine_fold(const std::vector<HarmonicRoot>& roots, int index, double f_root, double f_other, BranchEnd& end) {
    const auto& first = roots[static_cast<std::size_t>(index)];
    const auto& second = roots[static_cast<std::size_t>(index + 1)];
    const double x1 = first.damper_amplitudes_m[0], x2 = second.damper_amplitudes_m[0];
    // Bracket: halfway (in ln X) toward the neighbouring roots or the piece ends.
    pieces_at(damper_, f_root, scan_.x_min, scan_.x_max, pieces_);
    double lo = scan_.x_min, hi = scan_.x_max;
    for (const auto& p : pieces_)
      if (p.index == first.piece) {
        lo = p.lo_m;
        hi = p.hi_m;
      }
    if (index > 0 && roots[static_cast<std::size_t>(index - 1)].piece == first.piece)
      lo = std::sqrt(roots[static_cast<std::size_t>(index - 1)].damper_amplitudes_m[0] * x1);
    if (static_cast<std::size_t>(index + 2) < roots.size() &&
        roots[static_cast<std::size_t>(index + 2)].piece == first.piece)
      hi = std::sqrt(x2 * roots[static_cast<std::size_t>(index + 2)].damper_amplitudes_m[0]);
    op_.set_frequency(f_root);
    const double sign = op_.single_residual(std::sqrt(x1 * x2)) > 0.0 ? 1.0 : -1.0;
    double f_exists = f_root, f_gone = f_other, at = std::sqrt(x1 * x2);
    for (int iteration = 0; iteration < kRefineIterations; ++iteration) {
      const double f_mid = 0.5 * (f_exists + f_gone);
      op_.set_frequency(f_mid);
      double at_mid = 0.0;
      if (pair_extremum(lo, hi, sign, at_mid) > 0.0) {
        f_exists = f_mid;
        at = at_mid;
      } else {
        f_gone = f_mid;
      }
    }
    end.frequency_hz = f_exists;
    end.damper_amplitude_m = at;
  }

  void refine_single(const std::vector<HarmonicRoot>& roots, int index, double f_root, double f_other, bool refine,
                     BranchEnd& end) {
    const auto& root = roots[static_cast<std::size_t>(index)];
    pieces_at(damper_, f_root, scan_.x_min, scan_.x_max, pieces_);
    const Piece* piece = nullptr;
    for (const auto& p : pieces_)
      if (p.index == root.piece) piece = &p;
    const bool last_on_piece = static_cast<std::size_t>(index + 1) == roots.size() ||
                               roots[static_cast<std::size_t>(index + 1)].piece != root.piece;
    const bool first_on_piece = index == 0 || roots[static_cast<std::size_t>(index - 1)].piece != root.piece;
    // Which edge of the piece did the root leave through? The one it lies next to in ln X.
    const bool toward_hi = piece && (last_on_piece && (!first_on_piece || std::log(piece->hi_m / root.damper_amplitudes_m[0]) <
                                                                               std::log(root.damper_amplitudes_m[0] / piece->lo_m)));
    const double edge = piece ? (toward_hi ? piece->hi_m : piece->lo_m) : root.damper_amplitudes_m[0];
    const bool at_jump = piece && ((toward_hi && edge < scan_.x_max) || (!toward_hi && edge > scan_.x_min));
    end.kind = at_jump ? BranchEnd::Kind::kDiscontinuity : BranchEnd::Kind::kStrokeRange;
    if (!refine || !at_jump) return;
    // The root reaches the edge where the residual at the edge (inside the piece) changes sign.
    const double inside = toward_hi ? edge : edge * (1.0 + kInsidePiece);
    op_.set_frequency(f_root);
    const bool sign_root = op_.single_residual(inside) > 0.0;
    double f_exists = f_root, f_gone = f_other;
    for (int iteration = 0; iteration < kRefineIterations; ++iteration) {
      const double f_mid = 0.5 * (f_exists + f_gone);
      op_.set_frequency(f_mid);
      (((op_.single_residual(inside) > 0.0) == sign_root) ? f_exists : f_gone) = f_mid;
    }
    end.frequency_hz = f_exists;
    end.damper_amplitude_m = inside;
  }

  FrequencyOperator& op_;
  const Damper& damper_;
  const ScanSettings& scan_;
  std::vector<Piece> pieces_;
};

/// Peaks of a sampled response curve (NaN where none), half-power damping ratio. A
/// plateau (the response held at a loss model's jump: the damper amplitude pinned at the
/// onset over a band of frequencies) is one peak at the plateau's middle.
void find_peaks(const std::vector<double>& f, const std::vector<double>& c, std::size_t output,
                std::vector<ResponsePeak>& peaks) {
  const std::size_t n = c.size();
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (!(c[k] > c[k - 1])) continue;
    // Samples equal to c[k] up to round-off (1e-9 relative) belong to its plateau.
    std::size_t end = k;
    while (end + 1 < n && std::abs(c[end + 1] - c[k]) <= 1e-9 * c[k]) ++end;
    if (end + 1 >= n || !(c[end] >= c[end + 1])) {
      k = end;  // a shelf on the way up (or the curve's end), not a peak
      continue;
    }
    ResponsePeak peak;
    peak.output = output;
    peak.magnitude = c[k];
    peak.frequency_hz = end > k ? 0.5 * (f[k] + f[end])
                                : parabola_vertex(f[k - 1], c[k - 1], f[k], c[k], f[k + 1], c[k + 1]);
    const LevelCrossings half_power = level_crossings(f, c, k, end, c[k] / std::sqrt(2.0));
    const LevelCrossings band = outer_level_crossings(f, c, k, kResonanceBandFraction * c[k]);
    peak.band_centre_hz = 0.5 * (band.low_hz + band.high_hz);
    peak.damping_ratio = (half_power.high_hz - half_power.low_hz) / (2.0 * peak.frequency_hz);
    peaks.push_back(peak);
    k = end;
  }
}

}  // namespace

std::string_view to_string(Stability stability) {
  switch (stability) {
    case Stability::kStable: return "stable";
    case Stability::kUnstable: return "unstable";
    case Stability::kMarginal: return "marginal";
  }
  return "unknown";
}

std::vector<std::string> Excitation::validate(const ModalModel& model) const {
  std::vector<std::string> problems;
  if (!(std::abs(direction.norm() - 1.0) <= 1e-6))
    problems.push_back("excitation.direction = (" + format_number(direction.x(), 12) + ", " +
                       format_number(direction.y(), 12) + "): must be a unit vector");
  if (!(amplitude > 0.0 && std::isfinite(amplitude)))
    problems.push_back("excitation.amplitude = " + format_number(amplitude, 12) + ": must be > 0 and finite");
  if (kind == Kind::kBaseTranslation && model.base_participation.cols() != 2)
    problems.push_back("excitation.kind = base: the modal model has no base participation (Gamma)");
  if (kind == Kind::kPointForce) {
    bool found = false;
    for (const auto& p : model.points) found = found || p.name == point;
    if (!found) problems.push_back("excitation.point = \"" + point + "\": must name a point of the modal model");
  }
  return problems;
}

std::vector<std::string> HarmonicBalanceOptions::validate() const {
  std::vector<std::string> problems;
  if (frequencies_hz.empty()) problems.push_back("frequencies_hz: must hold at least one frequency");
  for (std::size_t k = 0; k < frequencies_hz.size(); ++k) {
    if (!(frequencies_hz[k] > 0.0 && std::isfinite(frequencies_hz[k])))
      problems.push_back("frequencies_hz[" + std::to_string(k) + "] = " + format_number(frequencies_hz[k], 12) +
                         ": must be > 0 and finite");
    else if (k > 0 && !(frequencies_hz[k] > frequencies_hz[k - 1]))
      problems.push_back("frequencies_hz[" + std::to_string(k) + "] = " + format_number(frequencies_hz[k], 12) +
                         ": must be > frequencies_hz[" + std::to_string(k - 1) + "]");
  }
  if (!(stroke_min_m >= 0.0 && std::isfinite(stroke_min_m)))
    problems.push_back("stroke_min_m = " + format_number(stroke_min_m, 12) + ": must be >= 0 and finite (0 = auto)");
  if (!(stroke_max_m >= 0.0 && std::isfinite(stroke_max_m)))
    problems.push_back("stroke_max_m = " + format_number(stroke_max_m, 12) + ": must be >= 0 and finite (0 = auto)");
  if (stroke_min_m > 0.0 && stroke_max_m > 0.0 && !(stroke_max_m > stroke_min_m))
    problems.push_back("stroke_max_m = " + format_number(stroke_max_m, 12) +
                       ": must be > stroke_min_m = " + format_number(stroke_min_m, 12));
  if (scan_points_per_decade < 4)
    problems.push_back("scan_points_per_decade = " + std::to_string(scan_points_per_decade) + ": must be >= 4");
  if (!(stroke_tolerance > 0.0 && stroke_tolerance <= 1e-3))
    problems.push_back("stroke_tolerance = " + format_number(stroke_tolerance, 12) + ": must be in (0, 1e-3]");
  if (max_newton_iterations < 1)
    problems.push_back("max_newton_iterations = " + std::to_string(max_newton_iterations) + ": must be >= 1");
  if (!(fixed_point_relaxation > 0.0 && fixed_point_relaxation <= 1.0))
    problems.push_back("fixed_point_relaxation = " + format_number(fixed_point_relaxation, 12) + ": must be in (0, 1]");
  for (auto& p : coupling.validate()) problems.push_back("coupling." + p);
  return problems;
}

std::string FrequencyResponse::brief_report() const {
  std::size_t roots = 0, unstable = 0;
  for (const auto& p : points)
    for (const auto& r : p.roots) {
      ++roots;
      unstable += r.stability == Stability::kUnstable;
    }
  std::size_t folds = 0, cliffs = 0, pinned = 0;
  for (const auto& p : points) pinned += !p.held_at_jump.empty();
  for (const auto& e : branch_ends) {
    folds += e.kind == BranchEnd::Kind::kFold;
    cliffs += e.kind == BranchEnd::Kind::kDiscontinuity;
  }
  std::ostringstream out;
  out << "harmonic balance: "
      << (outcome == Outcome::kConverged ? "converged" : "some roots not converged")
      << ", " << points.size() << " frequencies, " << roots << " roots (" << unstable << " unstable), " << folds
      << " folds, " << cliffs << " onset jumps, " << pinned << " frequencies held at a jump, " << peaks.size() << " peaks, " << loss_evaluations
      << " loss-model evaluations, " << solve_time_s << " s";
  return out.str();
}

FrequencyResponse harmonic_balance(const ModalModel& model, const std::vector<Damper>& dampers,
                                   const Excitation& excitation, const HarmonicBalanceOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::string> problems = options.validate();
  for (auto& p : excitation.validate(model)) problems.push_back(p);
  if (dampers.empty()) problems.push_back("dampers: must hold at least one damper");
  if (!problems.empty()) {
    std::string message = "harmonic_balance: invalid input";
    for (const auto& p : problems) message += "\n  " + p;
    throw std::invalid_argument(message);
  }
  const CoupledModel coupled = couple(model, dampers, options.coupling);
  std::vector<ResponseOutput> outputs = options.outputs;
  if (outputs.empty())
    for (const auto& d : dampers) outputs.push_back({d.name, d.point, d.drive_direction});
  for (const auto& o : outputs) point_of(model, o.point);

  FrequencyResponse response;
  for (const auto& o : outputs) response.output_names.push_back(o.name);
  FrequencyOperator op(coupled, model, excitation, outputs);

  // Scan range: the options or the union of all layers' ranges at the first frequency.
  ScanSettings scan{options.stroke_min_m, options.stroke_max_m, options.scan_points_per_decade,
                    options.stroke_tolerance};
  for (const auto& d : dampers) {
    const auto range = damper_stroke_range_m(d, options.frequencies_hz.front());
    if (options.stroke_min_m == 0.0) scan.x_min = scan.x_min == 0.0 ? range.min_m : std::min(scan.x_min, range.min_m);
    if (options.stroke_max_m == 0.0) scan.x_max = std::max(scan.x_max, range.max_m);
  }
  if (!(scan.x_min > 0.0 && scan.x_max > scan.x_min))
    throw std::invalid_argument("harmonic_balance: no stroke range: the dampers need layers or stroke_min_m/max_m");

  const bool single = dampers.size() == 1;
  ScanWorkspace work;
  Linker linker;
  std::vector<int> ended, born;
  BranchEndFinder ends(op, dampers[0], scan);
  response.points.resize(options.frequencies_hz.size());
  for (std::size_t k = 0; k < options.frequencies_hz.size(); ++k) {
    FrequencyPoint& point = response.points[k];
    point.frequency_hz = options.frequencies_hz[k];
    op.set_frequency(point.frequency_hz);
    point.linear_outputs.resize(outputs.size());
    for (std::size_t o = 0; o < outputs.size(); ++o)
      point.linear_outputs[o] = op.output_linear()[static_cast<Eigen::Index>(o)] / excitation.amplitude;
    if (single) {
      single_damper_roots(op, dampers[0], scan, work, point);
    } else {
      static const std::vector<HarmonicRoot> kNone;
      multi_damper_roots(op, scan, options, k > 0 ? response.points[k - 1].roots : kNone, point,
                         response.unconverged_starts);
    }
    if (k == 0) {
      linker.start(point.roots);
      continue;
    }
    const FrequencyPoint& previous = response.points[k - 1];
    linker.link(previous.roots, point.roots, ended, born);
    const bool refine = single && options.refine_branch_ends;
    ends.classify(previous.roots, ended, previous.frequency_hz, point.frequency_hz, refine, response.branch_ends);
    ends.classify(point.roots, born, point.frequency_hz, previous.frequency_hz, refine, response.branch_ends);
  }

  // Peaks of the highest stable response and of the linear FRF, per output.
  std::vector<double> f(response.points.size()), curve(response.points.size()), linear(response.points.size());
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    for (std::size_t k = 0; k < response.points.size(); ++k) {
      f[k] = response.points[k].frequency_hz;
      linear[k] = std::abs(response.points[k].linear_outputs[o]);
      curve[k] = kNaN;
      auto take = [&](double magnitude) { curve[k] = std::isfinite(curve[k]) ? std::max(curve[k], magnitude) : magnitude; };
      for (const auto& root : response.points[k].roots)
        if (root.stability != Stability::kUnstable) take(std::abs(root.outputs[o]));
      for (const auto& held : response.points[k].held_at_jump) take(std::abs(held.outputs[o]));
    }
    find_peaks(f, curve, o, response.peaks);
    find_peaks(f, linear, o, response.linear_peaks);
  }

  for (const auto& p : response.points)
    for (const auto& r : p.roots) response.loss_warnings |= r.loss_warnings;
  response.warnings = surrogate::describe_loss_warnings(response.loss_warnings);
  if (response.unconverged_starts > 0) {
    response.outcome = FrequencyResponse::Outcome::kSomeRootsNotConverged;
    response.warnings.push_back(std::to_string(response.unconverged_starts) +
                                " Newton starts did not converge: roots may be missing there");
  }
  response.loss_evaluations = op.evaluations();
  response.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return response;
}

}  // namespace pdamp::structure
