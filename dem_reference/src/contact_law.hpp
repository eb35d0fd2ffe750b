// Contact law of the reference DEM: the material-pair table, per-contact parameters
// and the force kernel (Hertz + calibrated damping, Mindlin spring, rolling resistance).
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "pdamp/dem_reference/world_options.hpp"
#include "pdamp/formulas/cor_models.hpp"
#include "pdamp/formulas/layered_contact.hpp"
#include "simd_lanes.hpp"

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
  /// 1/R*² of the rolling spring (k_r = k_t R*²), R* = (K·inv_hertz_modulus)² as the kernel
  /// forms it: the division the kernel would repeat every step, done once (same bits).
  double inv_radius_squared = 0.0;
  int pair_type = 0;           ///< index of the material pair
  int layer = -1;              ///< index of the wall-layer law (ContactLaw::layer_law); −1: Hertz
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

/// The contact law of a sphere material on a bonded wall layer of one thickness: the
/// layered force, damping and energy relative to Hertz's at χ = √(R*δ)/t, and the
/// damping γ_n that realises the pair's ε on it (docs/dem.md "Buffered walls").
struct WallLayerLaw {
  int pair_type = 0;
  double thickness_m = 0.0;
  double inv_thickness = 0.0;  ///< 1/t, 1/m
  formulas::LayeredContact contact;
  formulas::LayeredDampingTable damping;
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
  /// < 0 concave (cylinder mantle) curvature radius across the contact; layer_thickness_m
  /// > 0: the wall is the surface of a bonded layer of that thickness (WallLayerLaw).
  ContactParams particle_wall(double radius_i, double mass_i, int material_i, int wall_material,
                              double wall_radius_m, double layer_thickness_m = 0.0) const;
  /// γ_n realising ε(v) of the contact's pair (docs/theory.md §6): Hertz's via
  /// formulas::DampingTable, a layer's via its formulas::LayeredDampingTable.
  double damping_coefficient(const ContactParams& params, double impact_speed_m_s) const;
  const WallLayerLaw& layer_law(int index) const { return layers_[static_cast<std::size_t>(index)]; }
  /// The layered law of a contact relative to Hertz's at overlap δ (√δ given); all ones for Hertz.
  formulas::LayeredContact::HertzRatios hertz_ratios(const ContactParams& params, double root_delta) const {
    if (params.layer < 0) return {};
    const WallLayerLaw& l = layers_[static_cast<std::size_t>(params.layer)];
    const double root_r = params.stiffness * types_[static_cast<std::size_t>(params.pair_type)].inv_hertz_modulus;
    return l.contact.hertz_ratios(root_r * root_delta * l.inv_thickness);
  }
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
  std::vector<WallLayerLaw> layers_;     // one per (sphere material, layer) met in the compartments
};

/// The contacts one evaluation of the kernel serves, one per lane (lane l: params[l], …).
template <int N>
struct ContactLanes {
  const ContactParams* params[N];
  ContactHistory* history[N];
  double* rolling_torque[N];  ///< the contact's rolling spring torque on i (3 values), or null
                              ///< when its pair type has no rolling resistance
  ContactResult* out[N];
};

/// ContactKinematics of W::kWidth contacts, one per lane.
template <class W>
struct KinematicsLanes {
  W n[3];
  W delta;
  W v[3];
  W w[3];
};

/// Loads the kinematics of W::kWidth contacts into lanes (lane l from k[l]).
template <class W>
[[gnu::always_inline]] inline KinematicsLanes<W> load_kinematics(const ContactKinematics* const* k) {
  KinematicsLanes<W> out;
  for (int c = 0; c < 3; ++c) {
    out.n[c] = W::gather([&](int l) { return k[l]->n[c]; });
    out.v[c] = W::gather([&](int l) { return k[l]->v[c]; });
    out.w[c] = W::gather([&](int l) { return k[l]->w[c]; });
  }
  out.delta = W::gather([&](int l) { return k[l]->delta; });
  return out;
}

/// The tangential (or rolling) spring update shared by both springs, lane-wise: project
/// the stored vector s into the plane normal to n, apply the Mindlin stiffness change
/// without injecting energy, add −k·Δu, cap at the Coulomb limit. Returns the energy
/// dissipated in the step per lane, J. With kMasked only the lanes of `active` take the
/// rare paths (the others' results are to be discarded).
///
/// Why: with a stiffness k(δ) that changes during the contact, storing the
/// displacement (F = kξ) injects energy on loading and storing the force (ΔF = kΔξ)
/// injects it on unloading. We keep the force on loading and scale it with k on
/// unloading (Thornton et al. 2011): the stored energy |F|²/2k then only ever drops,
/// and the drop is counted as tangential dissipation (Mindlin's micro-slip hysteresis).
///
/// The projection drops the spring's normal component sn = s·n without restoring the
/// magnitude (docs/dem.md "Tangential", physics version 4): the contact plane turns by
/// ~1e-4 rad a step, so the part lost, |s|²q/2k with q = sn²/|s|² ~ 1e-8, is far below
/// the step's other terms, and it is counted in the ledger like the Mindlin drop (the
/// stored energy goes from |s|²/2k_prev to |r|²·ratio/2k_prev with |r|² = |s|² − sn²).
///
/// Branches are lane masks; the rare path (sliding) runs only when a lane needs it. Each
/// lane performs the operations of the scalar update in the scalar order (the width-1
/// instantiation is the scalar update).
template <class W, bool kMasked>
[[gnu::always_inline]] inline W update_spring(W* s, const W* n, W k, W inv_k, W inv_k_prev, const W* du, W cap,
                                             W cap_prev, typename W::Mask active) {
  using Mask = typename W::Mask;
  const W zero = W::splat(0.0);
  const W one = W::splat(1.0);
  const W half = W::splat(0.5);
  W loss = zero;
  const W s2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
  Mask turn = (inv_k_prev > zero) & (s2 > zero);
  if constexpr (kMasked) turn = turn & active;
  if (any(turn)) {
    const W sn = s[0] * n[0] + s[1] * n[1] + s[2] * n[2];
    const W r[3] = {s[0] - sn * n[0], s[1] - sn * n[1], s[2] - sn * n[2]};
    const W r2 = s2 - sn * sn;
    const W ratio = k * inv_k_prev;
    const Mask unloading = ratio < one;
    // Stored energy before, |s|²/2k_prev, minus after: |r|²·ratio/2k_prev on unloading
    // (the force scaled with k), |r|²/2k on loading (the force kept).
    const W loss_unloading = half * inv_k_prev * (s2 - r2 * ratio);
    const W loss_loading = half * (s2 * inv_k_prev - r2 * inv_k);
    const W turned_loss = select(unloading, loss_unloading, loss_loading);
    const W scale = select(unloading, ratio, one);
    // Every lane turning (a persisting contact in each: the common case) needs no select,
    // which costs three instructions a value without SSE4.1; the values are the same.
    if (all(turn)) {
      loss = turned_loss;
      for (int c = 0; c < 3; ++c) s[c] = r[c] * scale;
    } else {
      loss = select(turn, turned_loss, zero);
      for (int c = 0; c < 3; ++c) s[c] = select(turn, r[c] * scale, s[c]);
    }
  }
  for (int c = 0; c < 3; ++c) s[c] = s[c] - k * du[c];
  const W t2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
  Mask sliding = t2 > cap * cap;
  if constexpr (kMasked) sliding = sliding & active;
  if (any(sliding)) {
    const W t = sqrt(t2);
    // Energy of sliding: the mean Coulomb limit of the step times the slip (t − cap)/k.
    const W slid_loss = loss + half * (cap + cap_prev) * (t - cap) * inv_k;
    const W scale = cap / t;
    if (all(sliding)) {  // as above: the same values without selects
      loss = slid_loss;
      for (int c = 0; c < 3; ++c) s[c] = s[c] * scale;
    } else {
      loss = select(sliding, slid_loss, loss);
      for (int c = 0; c < 3; ++c) s[c] = select(sliding, s[c] * scale, s[c]);
    }
  }
  return loss;
}

/// The contact force kernel (docs/dem.md "Contact laws"), for W::kWidth contacts at once:
///   F_n = max(0, Kδ^{3/2} + γ_n√(m*K)δ^{1/4}δ̇),  k_t = 8G*√(R*δ),  k_r = k_t R*²,
///   |F_t| <= μF_n,  |M_r| <= μ_r R* F_n.
/// dt is the step; law is used once per contact, at first touch, for γ_n(ε(v)).
///
/// Written once over the lane type W (simd_lanes.hpp): Lanes1 is the scalar kernel,
/// Lanes2/LanesAvx2 evaluate two/four contacts in the lanes of a register. Why lanes:
/// the kernel is a chain of three square roots and two divisions whose latency, not the
/// arithmetic, bounds a scalar loop; contacts in lanes share the chain. Every lane runs
/// the same IEEE operations in the same order (no fused multiply-add: see
/// simd_lanes.hpp), so the results are bit for bit those of one-lane calls on the
/// contacts in lane order; each dissipation sum also receives lane 0's term first, then
/// lane 1's, and so on. Lanes whose pair type has no rolling resistance skip the rolling
/// spring (their rolling torque is zero and not stored).
template <class W>
[[gnu::always_inline]] inline void contact_force_lanes(const ContactLanes<W::kWidth>& c, const KinematicsLanes<W>& k,
                                                       double dt, const ContactLaw& law, StepDissipation& diss) {
  constexpr int kN = W::kWidth;
  using Mask = typename W::Mask;
  const PairType* type[kN];
  for (int l = 0; l < kN; ++l) type[l] = &law.type(c.params[l]->pair_type);
  const W zero = W::splat(0.0);
  const W one = W::splat(1.0);
  const W half = W::splat(0.5);
  const W step = W::splat(dt);
  const W* n = k.n;
  const W vn = k.v[0] * n[0] + k.v[1] * n[1] + k.v[2] * n[2];  // approach speed δ̇
  for (int l = 0; l < kN; ++l) {
    ContactHistory& h = *c.history[l];
    if (h.gamma < 0.0) {
      const double speed = lane(vn, l);
      h.gamma = law.damping_coefficient(*c.params[l], speed > 0.0 ? speed : 0.0);
    }
  }
  const W stiffness = W::gather([&](int l) { return c.params[l]->stiffness; });
  const W gamma = W::gather([&](int l) { return c.history[l]->gamma; });
  const W damping_scale = W::gather([&](int l) { return c.params[l]->damping_scale; });
  const W root = sqrt(k.delta);
  W f_elastic = stiffness * k.delta * root;
  W damping_rate = gamma * damping_scale * sqrt(root);
  // Contacts on a bonded wall layer: the layered law, F = Kδ^{3/2}G(χ) and the damping
  // scaled through its local stiffness (formulas::layered_realised_restitution). Hertz
  // lanes are multiplied by exactly 1, so their bits do not change.
  bool any_layer = false;
  for (int l = 0; l < kN; ++l) any_layer = any_layer || c.params[l]->layer >= 0;
  if (any_layer) {
    formulas::LayeredContact::HertzRatios ratios[kN];
    for (int l = 0; l < kN; ++l) ratios[l] = law.hertz_ratios(*c.params[l], lane(root, l));
    f_elastic = f_elastic * W::gather([&](int l) { return ratios[l].force; });
    damping_rate = damping_rate * W::gather([&](int l) { return ratios[l].damping; });
  }
  W f_n = f_elastic + damping_rate * vn;
  f_n = select(f_n < zero, zero, f_n);  // no tension: the contact ends when the force returns to zero
  const W f_damp = f_n - f_elastic;
  // Trapezoidal work of the damping force over the step's overlap change vn·dt.
  const W damping = half * (W::gather([&](int l) { return c.history[l]->fd_prev; }) + f_damp) * vn * step;
  for (int l = 0; l < kN; ++l) diss.normal_damping += lane(damping, l);
  scatter(f_damp, [&](int l) -> double& { return c.history[l]->fd_prev; });

  const W kt = stiffness * W::gather([&](int l) { return type[l]->tangential_ratio; }) * root;
  const W du[3] = {(k.v[0] - vn * n[0]) * step, (k.v[1] - vn * n[1]) * step, (k.v[2] - vn * n[2]) * step};
  const W mu = W::gather([&](int l) { return type[l]->friction; });
  const W cap = mu * f_n;
  const W inv_kt = one / kt;
  const W inv_kt_prev = W::gather([&](int l) { return c.history[l]->inv_kt_prev; });
  const W fn_prev = W::gather([&](int l) { return c.history[l]->fn_prev; });
  W ft[3];
  for (int d = 0; d < 3; ++d) ft[d] = W::gather([&](int l) { return c.history[l]->ft[d]; });
  const W friction_loss = update_spring<W, false>(ft, n, kt, inv_kt, inv_kt_prev, du, cap, mu * fn_prev, Mask{});
  for (int l = 0; l < kN; ++l) diss.friction += lane(friction_loss, l);
  for (int d = 0; d < 3; ++d) scatter(ft[d], [&](int l) -> double& { return c.history[l]->ft[d]; });
  const W minus_fn = -f_n;
  for (int d = 0; d < 3; ++d) scatter(minus_fn * n[d] + ft[d], [&](int l) -> double& { return c.out[l]->f[d]; });
  scatter(n[1] * ft[2] - n[2] * ft[1], [&](int l) -> double& { return c.out[l]->c[0]; });
  scatter(n[2] * ft[0] - n[0] * ft[2], [&](int l) -> double& { return c.out[l]->c[1]; });
  scatter(n[0] * ft[1] - n[1] * ft[0], [&](int l) -> double& { return c.out[l]->c[2]; });

  const W mu_r = W::gather([&](int l) { return type[l]->rolling_friction; });
  const Mask rolling = mu_r > zero;
  if (any(rolling)) {
    const W root_r = stiffness * W::gather([&](int l) { return type[l]->inv_hertz_modulus; });  // √R*
    const W r_eff = root_r * root_r;
    const W lever = mu_r * r_eff;
    const W wn = k.w[0] * n[0] + k.w[1] * n[1] + k.w[2] * n[2];
    const W dtheta[3] = {(k.w[0] - wn * n[0]) * step, (k.w[1] - wn * n[1]) * step, (k.w[2] - wn * n[2]) * step};
    const W r2 = r_eff * r_eff;
    const W inv_r2 = W::gather([&](int l) { return c.params[l]->inv_radius_squared; });
    W mr[3];
    for (int d = 0; d < 3; ++d) {
      mr[d] = W::gather([&](int l) { return type[l]->rolling_friction > 0.0 ? c.rolling_torque[l][d] : 0.0; });
    }
    const W rolling_loss = update_spring<W, (kN > 1)>(mr, n, kt * r2, inv_kt * inv_r2, inv_kt_prev * inv_r2, dtheta,
                                                      lever * f_n, lever * fn_prev, rolling);
    for (int l = 0; l < kN; ++l) {
      ContactResult& out = *c.out[l];
      if (lane(rolling, l)) {
        diss.rolling += lane(rolling_loss, l);
        for (int d = 0; d < 3; ++d) out.m[d] = c.rolling_torque[l][d] = lane(mr[d], l);
      } else {
        out.m[0] = out.m[1] = out.m[2] = 0.0;
      }
    }
  } else {
    for (int l = 0; l < kN; ++l) c.out[l]->m[0] = c.out[l]->m[1] = c.out[l]->m[2] = 0.0;
  }
  scatter(inv_kt, [&](int l) -> double& { return c.history[l]->inv_kt_prev; });
  scatter(f_n, [&](int l) -> double& { return c.history[l]->fn_prev; });
  diss.contacts += kN;
}

/// Energy stored in a contact: (2/5)Kδ^{5/2} (times W(χ) on a layer) + |F_t|²/2k_t +
/// |M_r|²/2k_r, J. mr: the rolling spring torque, as ContactLanes::rolling_torque.
double stored_energy(const ContactParams& p, const ContactLaw& law, const ContactHistory& h, const double* mr,
                     double delta);

}  // namespace pdamp::dem_reference::detail
