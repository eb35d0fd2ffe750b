// Contact law of the reference DEM: the material-pair table, per-contact parameters
// and the force kernel (Hertz + calibrated damping, Mindlin spring, rolling resistance).
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include <emmintrin.h>

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

/// contact_force for two contacts at once, one per lane of an SSE2 register (part of
/// x86-64 itself: no -march needed). Why: the kernel is a chain of three square roots
/// and two divisions whose latency, not the arithmetic, bounds a scalar loop; two
/// contacts in lanes share the chain. Every lane runs the operations of contact_force
/// in the same order (IEEE arithmetic is exact per lane and SSE2 has no fused
/// multiply-add), so the results are bit for bit those of two contact_force calls, a
/// then b; the dissipation sums also receive a's terms before b's. Branches of the
/// scalar kernel become lane masks; its rare paths (first touch, a spring turned by
/// more than 0.6°, sliding) run only when a lane needs them. Pairs with rolling
/// resistance take the scalar kernel.
[[gnu::always_inline]] inline void contact_force_2(const ContactParams& pa, ContactHistory& ha, double* mra,
                                                   const ContactKinematics& ka, const ContactParams& pb,
                                                   ContactHistory& hb, double* mrb, const ContactKinematics& kb,
                                                   double dt, const ContactLaw& law, ContactResult& oa,
                                                   ContactResult& ob, StepDissipation& diss) {
  const PairType& ta = law.type(pa.pair_type);
  const PairType& tb = law.type(pb.pair_type);
  if (ta.rolling_friction > 0.0 || tb.rolling_friction > 0.0) {
    contact_force(pa, ha, mra, ka, dt, law, oa, diss);
    contact_force(pb, hb, mrb, kb, dt, law, ob, diss);
    return;
  }
  using V = __m128d;
  const auto pack = [](double a, double b) { return _mm_set_pd(b, a); };  // lane 0 = a
  const auto blend = [](V mask, V yes, V no) { return _mm_or_pd(_mm_and_pd(mask, yes), _mm_andnot_pd(mask, no)); };
  const auto lane0 = [](V v) { return _mm_cvtsd_f64(v); };
  const auto lane1 = [](V v) { return _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); };
  const auto put = [](V v, double& a, double& b) {  // lane 0 to a, lane 1 to b
    _mm_storel_pd(&a, v);
    _mm_storeh_pd(&b, v);
  };
  const V zero = _mm_setzero_pd();
  const V one = _mm_set1_pd(1.0);
  const V half = _mm_set1_pd(0.5);
  const V step = _mm_set1_pd(dt);
  const V n0 = pack(ka.n[0], kb.n[0]), n1 = pack(ka.n[1], kb.n[1]), n2 = pack(ka.n[2], kb.n[2]);
  const V v0 = pack(ka.v[0], kb.v[0]), v1 = pack(ka.v[1], kb.v[1]), v2 = pack(ka.v[2], kb.v[2]);
  const V vn = _mm_add_pd(_mm_add_pd(_mm_mul_pd(v0, n0), _mm_mul_pd(v1, n1)), _mm_mul_pd(v2, n2));
  if (ha.gamma < 0.0) ha.gamma = law.damping_coefficient(pa.pair_type, lane0(vn) > 0.0 ? lane0(vn) : 0.0);
  if (hb.gamma < 0.0) hb.gamma = law.damping_coefficient(pb.pair_type, lane1(vn) > 0.0 ? lane1(vn) : 0.0);
  const V delta = pack(ka.delta, kb.delta);
  const V stiffness = pack(pa.stiffness, pb.stiffness);
  const V root = _mm_sqrt_pd(delta);
  const V f_elastic = _mm_mul_pd(_mm_mul_pd(stiffness, delta), root);
  V f_n = _mm_add_pd(
      f_elastic,
      _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(pack(ha.gamma, hb.gamma), pack(pa.damping_scale, pb.damping_scale)),
                            _mm_sqrt_pd(root)),
                 vn));
  f_n = _mm_andnot_pd(_mm_cmplt_pd(f_n, zero), f_n);  // no tension (+0, as the scalar kernel)
  const V f_damp = _mm_sub_pd(f_n, f_elastic);
  const V damping =
      _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(half, _mm_add_pd(pack(ha.fd_prev, hb.fd_prev), f_damp)), vn), step);
  diss.normal_damping += lane0(damping);
  diss.normal_damping += lane1(damping);
  put(f_damp, ha.fd_prev, hb.fd_prev);

  const V kt = _mm_mul_pd(_mm_mul_pd(stiffness, pack(ta.tangential_ratio, tb.tangential_ratio)), root);
  const V du0 = _mm_mul_pd(_mm_sub_pd(v0, _mm_mul_pd(vn, n0)), step);
  const V du1 = _mm_mul_pd(_mm_sub_pd(v1, _mm_mul_pd(vn, n1)), step);
  const V du2 = _mm_mul_pd(_mm_sub_pd(v2, _mm_mul_pd(vn, n2)), step);
  const V mu = pack(ta.friction, tb.friction);
  const V cap = _mm_mul_pd(mu, f_n);
  const V inv_kt = _mm_div_pd(one, kt);
  const V cap_prev = _mm_mul_pd(mu, pack(ha.fn_prev, hb.fn_prev));
  const V inv_kt_prev = pack(ha.inv_kt_prev, hb.inv_kt_prev);

  // update_spring, lane-wise.
  V s0 = pack(ha.ft[0], hb.ft[0]), s1 = pack(ha.ft[1], hb.ft[1]), s2 = pack(ha.ft[2], hb.ft[2]);
  V loss = zero;
  const V sq = _mm_add_pd(_mm_add_pd(_mm_mul_pd(s0, s0), _mm_mul_pd(s1, s1)), _mm_mul_pd(s2, s2));
  const V turn = _mm_and_pd(_mm_cmpgt_pd(inv_kt_prev, zero), _mm_cmpgt_pd(sq, zero));
  if (_mm_movemask_pd(turn) != 0) {
    const V sn = _mm_add_pd(_mm_add_pd(_mm_mul_pd(s0, n0), _mm_mul_pd(s1, n1)), _mm_mul_pd(s2, n2));
    const V r0 = _mm_sub_pd(s0, _mm_mul_pd(sn, n0));
    const V r1 = _mm_sub_pd(s1, _mm_mul_pd(sn, n1));
    const V r2 = _mm_sub_pd(s2, _mm_mul_pd(sn, n2));
    const V q = _mm_div_pd(_mm_mul_pd(sn, sn), sq);
    const V small = _mm_cmplt_pd(q, _mm_set1_pd(1e-4));
    V keep = _mm_add_pd(one, _mm_mul_pd(half, q));
    if ((_mm_movemask_pd(_mm_andnot_pd(small, turn))) != 0) {
      const V exact = _mm_and_pd(_mm_cmplt_pd(q, one), _mm_sqrt_pd(_mm_div_pd(one, _mm_sub_pd(one, q))));
      keep = blend(small, keep, exact);
    }
    const V ratio = _mm_mul_pd(kt, inv_kt_prev);
    const V unloading = _mm_cmplt_pd(ratio, one);
    const V loss_unloading = _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(half, sq), inv_kt_prev), _mm_sub_pd(one, ratio));
    const V loss_loading = _mm_mul_pd(_mm_mul_pd(half, sq), _mm_sub_pd(inv_kt_prev, inv_kt));
    loss = _mm_and_pd(turn, blend(unloading, loss_unloading, loss_loading));
    const V scale = blend(unloading, _mm_mul_pd(keep, ratio), keep);
    s0 = blend(turn, _mm_mul_pd(r0, scale), s0);
    s1 = blend(turn, _mm_mul_pd(r1, scale), s1);
    s2 = blend(turn, _mm_mul_pd(r2, scale), s2);
  }
  s0 = _mm_sub_pd(s0, _mm_mul_pd(kt, du0));
  s1 = _mm_sub_pd(s1, _mm_mul_pd(kt, du1));
  s2 = _mm_sub_pd(s2, _mm_mul_pd(kt, du2));
  const V t2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(s0, s0), _mm_mul_pd(s1, s1)), _mm_mul_pd(s2, s2));
  const V sliding = _mm_cmpgt_pd(t2, _mm_mul_pd(cap, cap));
  if (_mm_movemask_pd(sliding) != 0) {
    const V t = _mm_sqrt_pd(t2);
    const V slip = _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(half, _mm_add_pd(cap, cap_prev)), _mm_sub_pd(t, cap)), inv_kt);
    loss = blend(sliding, _mm_add_pd(loss, slip), loss);
    const V scale = _mm_div_pd(cap, t);
    s0 = blend(sliding, _mm_mul_pd(s0, scale), s0);
    s1 = blend(sliding, _mm_mul_pd(s1, scale), s1);
    s2 = blend(sliding, _mm_mul_pd(s2, scale), s2);
  }
  diss.friction += lane0(loss);
  diss.friction += lane1(loss);
  put(s0, ha.ft[0], hb.ft[0]);
  put(s1, ha.ft[1], hb.ft[1]);
  put(s2, ha.ft[2], hb.ft[2]);

  const V minus_fn = _mm_xor_pd(f_n, _mm_set1_pd(-0.0));
  put(_mm_add_pd(_mm_mul_pd(minus_fn, n0), s0), oa.f[0], ob.f[0]);
  put(_mm_add_pd(_mm_mul_pd(minus_fn, n1), s1), oa.f[1], ob.f[1]);
  put(_mm_add_pd(_mm_mul_pd(minus_fn, n2), s2), oa.f[2], ob.f[2]);
  put(_mm_sub_pd(_mm_mul_pd(n1, s2), _mm_mul_pd(n2, s1)), oa.c[0], ob.c[0]);
  put(_mm_sub_pd(_mm_mul_pd(n2, s0), _mm_mul_pd(n0, s2)), oa.c[1], ob.c[1]);
  put(_mm_sub_pd(_mm_mul_pd(n0, s1), _mm_mul_pd(n1, s0)), oa.c[2], ob.c[2]);
  oa.m[0] = oa.m[1] = oa.m[2] = 0.0;
  ob.m[0] = ob.m[1] = ob.m[2] = 0.0;
  put(inv_kt, ha.inv_kt_prev, hb.inv_kt_prev);
  put(f_n, ha.fn_prev, hb.fn_prev);
  diss.contacts += 2;
}

/// Energy stored in a contact: (2/5)Kδ^{5/2} + |F_t|²/2k_t + |M_r|²/2k_r, J. mr as in
/// contact_force.
double stored_energy(const ContactParams& p, const PairType& type, const ContactHistory& h, const double* mr,
                     double delta);

}  // namespace pdamp::dem_reference::detail
