// Contact law of the reference DEM: the material-pair table, per-contact parameters
// and the force kernel (Hertz + calibrated damping, Mindlin spring, rolling resistance).
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "pdamp/dem_reference/world_options.hpp"
#include "pdamp/formulas/cor_models.hpp"

namespace pdamp::dem_reference::detail {

/// Parameters of one material pair (per-contact parameters scale with R*, m*).
struct PairType {
  double tangential_ratio = 0.0;    ///< 6G*/E*: k_t = K·tangential_ratio·√δ (= 8G*√(R*δ))
  double friction = 0.0;            ///< μ
  double rolling_friction = 0.0;    ///< μ_r (0: no rolling resistance)
  double inv_hertz_modulus = 0.0;   ///< 1/((4/3)E*): √R* = K·inv_hertz_modulus, 1/Pa
};

/// Parameters of one contact, fixed while it lasts (set at first touch).
struct ContactParams {
  double stiffness = 0.0;      ///< K = (4/3)E*√R*, N/m^{3/2}
  double damping_scale = 0.0;  ///< √(m*K), kg^{1/2} N^{1/2} m^{-3/4}
  int pair_type = 0;           ///< index of the material pair
};

/// History of one contact. inv_kt_prev = 0 marks "not in contact at the last step".
/// The rolling spring torque is kept apart (only pairs with rolling resistance use it).
struct ContactHistory {
  double ft[3] = {0.0, 0.0, 0.0};  ///< tangential spring force on particle i, N
  double inv_kt_prev = 0.0;        ///< 1/k_t at the last step, m/N (stored inverted: saves divisions)
  double gamma = -1.0;             ///< γ_n set at first touch from ε(v_impact); < 0 = not yet touched
  double fd_prev = 0.0;            ///< realised damping force at the last step, N
  double fn_prev = 0.0;            ///< normal force at the last step, N
};

/// Geometry and relative motion of one contact at the current step.
struct ContactKinematics {
  double n[3];      ///< unit normal from particle i towards j (or into the wall)
  double delta;     ///< overlap, m, > 0
  double v[3];      ///< velocity of i's contact point relative to j's (half step), m/s
  double w[3];      ///< ω_i − ω_j (or − ω_container), rad/s
};

/// What the contact applies to particle i (j receives −force, arm_j·c − m).
struct ContactResult {
  double f[3];  ///< force on i, N
  double c[3];  ///< n × F_t: the tangential torque on i is R_i·c, on j R_j·c, N
  double m[3];  ///< rolling torque on i, N·m
};

/// Energy dissipated during one step, summed over contacts, J.
struct StepDissipation {
  double normal_damping = 0.0;
  double friction = 0.0;
  double rolling = 0.0;
  double max_overlap_ratio = 0.0;  ///< max δ/r_min seen
  int contacts = 0;
};

/// Material-pair table: E*, G*, μ, μ_r and the restitution model of every pair.
class ContactLaw {
 public:
  explicit ContactLaw(const WorldOptions& options);

  int pair_type(int material_a, int material_b) const { return material_a * materials_ + material_b; }
  /// Parameters of a sphere–sphere contact.
  ContactParams particle_pair(double radius_i, double mass_i, int material_i, double radius_j,
                              double mass_j, int material_j) const;
  /// Parameters of a sphere–wall contact; wall_radius_m: 0 flat, > 0 convex (pin),
  /// < 0 concave (cylinder mantle) curvature radius across the contact.
  ContactParams particle_wall(double radius_i, double mass_i, int material_i, int wall_material,
                              double wall_radius_m) const;
  /// γ_n realising ε(v) of the pair (PHYSICS.md §6, via formulas::DampingTable).
  double damping_coefficient(int pair_type, double impact_speed_m_s) const;
  double effective_modulus(int material_a, int material_b) const {
    return e_star_[static_cast<std::size_t>(pair_type(material_a, material_b))];
  }
  const PairType& type(int pair_type) const { return types_[static_cast<std::size_t>(pair_type)]; }
  /// True if any material pair has rolling resistance (contacts then keep a rolling torque).
  bool any_rolling_friction() const;

 private:
  int materials_ = 0;
  std::vector<double> e_star_;           // per pair type, Pa
  std::vector<PairType> types_;
  std::vector<std::shared_ptr<const formulas::RestitutionModel>> restitution_;
  std::vector<double> constant_gamma_;   // γ_n for constant-ε pairs, NaN otherwise
};

/// The tangential (or rolling) spring update shared by both springs: rotate the stored
/// vector into the plane normal to n keeping its magnitude, apply the Mindlin
/// stiffness change without injecting energy, add −k·Δu, cap at the Coulomb limit.
/// Returns the energy dissipated in the step, J.
///
/// Why: with a stiffness k(δ) that changes during the contact, storing the
/// displacement (F = kξ) injects energy on loading and storing the force (ΔF = kΔξ)
/// injects it on unloading. We keep the force on loading and scale it with k on
/// unloading (Thornton et al. 2011): the stored energy |F|²/2k then only ever drops,
/// and the drop is counted as tangential dissipation (Mindlin's micro-slip hysteresis).
[[gnu::always_inline]] inline double update_spring(double* s, const double* n, double k, double inv_k,
                                                  double inv_k_prev, const double* du, double cap, double cap_prev) {
  double loss = 0.0;
  if (inv_k_prev > 0.0) {
    const double s2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
    if (s2 > 0.0) {
      const double sn = s[0] * n[0] + s[1] * n[1] + s[2] * n[2];
      s[0] -= sn * n[0];
      s[1] -= sn * n[1];
      s[2] -= sn * n[2];
      // The contact plane turns by a tiny angle per step: q = |s·n|²/|s|² ~ 1e-8, so the
      // first-order magnitude correction 1 + q/2 is exact to round-off; exact otherwise.
      const double q = sn * sn / s2;
      const double keep = q < 1e-4 ? 1.0 + 0.5 * q : (q < 1.0 ? std::sqrt(1.0 / (1.0 - q)) : 0.0);
      const double ratio = k * inv_k_prev;
      double scale = keep;
      if (ratio < 1.0) {
        loss = 0.5 * s2 * inv_k_prev * (1.0 - ratio);
        scale *= ratio;
      } else {
        loss = 0.5 * s2 * (inv_k_prev - inv_k);
      }
      s[0] *= scale;
      s[1] *= scale;
      s[2] *= scale;
    }
  }
  s[0] -= k * du[0];
  s[1] -= k * du[1];
  s[2] -= k * du[2];
  const double t2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
  if (t2 > cap * cap) {
    const double t = std::sqrt(t2);
    // Energy of sliding: the mean Coulomb limit of the step times the slip (t − cap)/k.
    loss += 0.5 * (cap + cap_prev) * (t - cap) * inv_k;
    const double scale = cap / t;
    s[0] *= scale;
    s[1] *= scale;
    s[2] *= scale;
  }
  return loss;
}

/// The contact force kernel (docs/dem.md "Contact laws"):
///   F_n = max(0, Kδ^{3/2} + γ_n√(m*K)δ^{1/4}δ̇),  k_t = 8G*√(R*δ),  k_r = k_t R*²,
///   |F_t| <= μF_n,  |M_r| <= μ_r R* F_n.
/// mr: the contact's rolling spring torque on i (N·m, 3 values), used only when the
/// pair type has rolling resistance (may be null otherwise). dt is the step; law is used
/// once per contact, at first touch, for γ_n(ε(v)).
[[gnu::always_inline]] inline void contact_force(const ContactParams& p, ContactHistory& h, double* mr,
                                                 const ContactKinematics& k, double dt, const ContactLaw& law,
                                                 ContactResult& out, StepDissipation& diss) {
  const double* n = k.n;
  const PairType& type = law.type(p.pair_type);
  const double vn = k.v[0] * n[0] + k.v[1] * n[1] + k.v[2] * n[2];  // approach speed δ̇
  if (h.gamma < 0.0) h.gamma = law.damping_coefficient(p.pair_type, vn > 0.0 ? vn : 0.0);
  const double root = std::sqrt(k.delta);
  const double f_elastic = p.stiffness * k.delta * root;
  double f_n = f_elastic + h.gamma * p.damping_scale * std::sqrt(root) * vn;
  if (f_n < 0.0) f_n = 0.0;  // no tension: the contact ends when the force returns to zero
  const double f_damp = f_n - f_elastic;
  // Trapezoidal work of the damping force over the step's overlap change vn·dt.
  diss.normal_damping += 0.5 * (h.fd_prev + f_damp) * vn * dt;
  h.fd_prev = f_damp;

  const double kt = p.stiffness * type.tangential_ratio * root;
  const double du[3] = {(k.v[0] - vn * n[0]) * dt, (k.v[1] - vn * n[1]) * dt,
                        (k.v[2] - vn * n[2]) * dt};
  const double cap = type.friction * f_n;
  const double inv_kt = 1.0 / kt;
  diss.friction += update_spring(h.ft, n, kt, inv_kt, h.inv_kt_prev, du, cap, type.friction * h.fn_prev);
  out.f[0] = -f_n * n[0] + h.ft[0];
  out.f[1] = -f_n * n[1] + h.ft[1];
  out.f[2] = -f_n * n[2] + h.ft[2];
  out.c[0] = n[1] * h.ft[2] - n[2] * h.ft[1];
  out.c[1] = n[2] * h.ft[0] - n[0] * h.ft[2];
  out.c[2] = n[0] * h.ft[1] - n[1] * h.ft[0];

  if (type.rolling_friction > 0.0) {
    const double root_r = p.stiffness * type.inv_hertz_modulus;  // √R*
    const double r_eff = root_r * root_r;
    const double lever = type.rolling_friction * r_eff;
    const double wn = k.w[0] * n[0] + k.w[1] * n[1] + k.w[2] * n[2];
    const double dtheta[3] = {(k.w[0] - wn * n[0]) * dt, (k.w[1] - wn * n[1]) * dt,
                              (k.w[2] - wn * n[2]) * dt};
    const double r2 = r_eff * r_eff;
    const double inv_r2 = 1.0 / r2;
    diss.rolling += update_spring(mr, n, kt * r2, inv_kt * inv_r2, h.inv_kt_prev * inv_r2, dtheta, lever * f_n,
                                  lever * h.fn_prev);
    out.m[0] = mr[0];
    out.m[1] = mr[1];
    out.m[2] = mr[2];
  } else {
    out.m[0] = out.m[1] = out.m[2] = 0.0;
  }
  h.inv_kt_prev = inv_kt;
  h.fn_prev = f_n;
  ++diss.contacts;
}

/// Energy stored in a contact: (2/5)Kδ^{5/2} + |F_t|²/2k_t + |M_r|²/2k_r, J. mr as in
/// contact_force.
double stored_energy(const ContactParams& p, const PairType& type, const ContactHistory& h, const double* mr,
                     double delta);

}  // namespace pdamp::dem_reference::detail
