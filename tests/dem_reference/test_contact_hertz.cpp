// Single normal impacts reproduce the coefficient-of-restitution model.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;
using dem_test::box_world;

constexpr double kRadius = 0.005;

/// Rebound/approach speed ratio of one sphere hitting the −x wall at speed v.
double wall_restitution(const dr::WorldOptions& options, double v) {
  dr::World world(options);
  // Start 20 steps of flight from the wall so that the approach is resolved.
  const double gap = 20.0 * v * world.time_step_s();
  world.set_particle_state(0, {-0.1 + kRadius + gap, 0.0, 0.0}, {-v, 0.0, 0.0}, {0.0, 0.0, 0.0});
  dem_test::run_one_impact(world, 2'000'000);
  return world.velocity(0)[0] / v;
}

/// Relative rebound/approach speed ratio of two equal spheres meeting head on at v.
double pair_restitution(const dr::WorldOptions& options, double v) {
  dr::World world(options);
  const double gap = 20.0 * v * world.time_step_s();
  world.set_particle_state(0, {-kRadius - 0.5 * gap, 0.0, 0.0}, {0.5 * v, 0.0, 0.0}, {0.0, 0.0, 0.0});
  world.set_particle_state(1, {kRadius + 0.5 * gap, 0.0, 0.0}, {-0.5 * v, 0.0, 0.0}, {0.0, 0.0, 0.0});
  dem_test::run_one_impact(world, 2'000'000);
  return (world.velocity(1)[0] - world.velocity(0)[0]) / v;
}

}  // namespace

// Reference: the target ε is the model's input; the calibrated damping must realise it
// in the explicit DEM. Tolerance 2%, the DEM's for single impacts: the 50-step resolution of the contact
// and the half-step velocity in the damping term cost well under 1%.
TEST_CASE("sphere-wall and sphere-sphere impacts reproduce a constant restitution", "[dem_reference]") {
  for (const double eps : {0.3, 0.5, 0.7, 0.9, 0.95}) {
    auto options = box_world(1, kRadius, eps, 0.3);
    for (const double v : {0.1, 1.0}) {
      INFO("epsilon " << eps << ", v " << v);
      CHECK(wall_restitution(options, v) == Approx(eps).epsilon(0.02));
    }
    options.compartments.front().particles.front().count = 2;
    INFO("sphere-sphere, epsilon " << eps);
    CHECK(pair_restitution(options, 1.0) == Approx(eps).epsilon(0.02));
  }
}

// Reference: the table itself; at its nodes the interpolated ε(v) equals the tabulated
// value, so the impact at that speed must return it (2%, as above).
TEST_CASE("impacts reproduce a tabulated restitution at 0.05 to 3 m/s", "[dem_reference]") {
  const std::vector<double> speeds{0.05, 0.1, 0.3, 1.0, 3.0};
  const std::vector<double> values{0.95, 0.9, 0.8, 0.65, 0.5};
  auto options = box_world(1, kRadius, 0.8, 0.3);
  options.default_pair.restitution.table_speeds_m_s = speeds;
  options.default_pair.restitution.table_values = values;
  options.integration.max_impact_speed_m_s = 3.0;
  for (std::size_t k = 0; k < speeds.size(); ++k) {
    INFO("v " << speeds[k]);
    CHECK(wall_restitution(options, speeds[k]) == Approx(values[k]).epsilon(0.02));
  }
  options.compartments.front().particles.front().count = 2;
  for (std::size_t k = 0; k < speeds.size(); ++k) {
    INFO("sphere-sphere, v " << speeds[k]);
    CHECK(pair_restitution(options, speeds[k]) == Approx(values[k]).epsilon(0.02));
  }
}

// ---- The contact kernel in lanes ------------------------------------------------------

#include <cstdint>
#include <cstring>
#include <random>

#include "../../dem_reference/src/contact_law.hpp"

namespace {

namespace dd = pdamp::dem_reference::detail;

/// One contact as the kernel sees it: parameters, history, rolling torque, the result.
struct LaneContact {
  dd::ContactParams params;
  dd::ContactHistory history;
  double torque[3] = {0.0, 0.0, 0.0};
  bool rolling = false;
  dd::ContactResult out{};
};

/// Evaluates all contacts W::kWidth at a time, in order (the count is a multiple of 4).
template <class W>
void evaluate_in_lanes(std::vector<LaneContact>& contacts, const std::vector<dd::ContactKinematics>& kin, double dt,
                       const dd::ContactLaw& law, dd::StepDissipation& diss) {
  constexpr int kN = W::kWidth;
  for (std::size_t c = 0; c + kN <= contacts.size(); c += kN) {
    dd::ContactLanes<kN> lanes;
    const dd::ContactKinematics* k[kN];
    for (int l = 0; l < kN; ++l) {
      LaneContact& one = contacts[c + static_cast<std::size_t>(l)];
      lanes.params[l] = &one.params;
      lanes.history[l] = &one.history;
      lanes.rolling_torque[l] = one.rolling ? one.torque : nullptr;  // null: must not be touched
      lanes.out[l] = &one.out;
      k[l] = &kin[c + static_cast<std::size_t>(l)];
    }
    dd::contact_force_lanes<W>(lanes, dd::load_kinematics<W>(k), dt, law, diss);
  }
}

bool same_bits(const double* a, const double* b, std::size_t count) {
  return std::memcmp(a, b, count * sizeof(double)) == 0;
}

/// Runs `steps` steps of random contacts of four material pairs (with and without rolling
/// resistance, constant and tabulated ε) through lanes of type W; returns the contacts and
/// the dissipation. Every path of the kernel is taken: first touch, a spring turned by a
/// large angle, unloading, sliding, tension (separating faster than the damping allows).
template <class W>
std::pair<std::vector<LaneContact>, dd::StepDissipation> random_contacts_in_lanes(int steps) {
  namespace dr = pdamp::dem_reference;
  dr::WorldOptions o;
  dr::MaterialOptions soft;
  soft.name = "soft";
  soft.material.youngs_modulus_pa = 5e9;
  o.materials.push_back(soft);
  o.default_pair.rolling_friction = 0.02;
  dr::ContactPairOptions mixed;
  mixed.material_a = 0;
  mixed.material_b = 1;
  mixed.friction = 0.5;
  mixed.restitution.table_speeds_m_s = {0.0, 1.0, 3.0};
  mixed.restitution.table_values = {0.9, 0.7, 0.5};
  dr::ContactPairOptions soft_pair;
  soft_pair.material_a = 1;
  soft_pair.material_b = 1;
  soft_pair.rolling_friction = 0.05;
  o.pairs = {mixed, soft_pair};
  const dd::ContactLaw law(o);
  std::mt19937_64 rng(11);
  const auto uniform = [&](double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;  // exact, portable
  };
  const auto unit = [&](double* n) {
    const double a[3] = {uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
    const double inv = 1.0 / std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int d = 0; d < 3; ++d) n[d] = a[d] * inv;
  };
  constexpr std::size_t kContacts = 256;
  std::vector<LaneContact> contacts(kContacts);
  std::vector<dd::ContactKinematics> kin(kContacts);
  for (std::size_t c = 0; c < kContacts; ++c) {
    LaneContact& one = contacts[c];
    const int mi = static_cast<int>(rng() % 2), mj = static_cast<int>(rng() % 2);
    one.params = law.particle_pair(0.005, 4e-3, mi, 0.004, 2e-3, mj);
    one.rolling = law.type(one.params.pair_type).rolling_friction > 0.0;
    if (c % 4 != 0) {  // in touch already: a stored spring (and rolling torque), γ known
      one.history.gamma = law.damping_coefficient(one.params, 0.5);
      one.history.inv_kt_prev = uniform(0.5e-6, 2e-6);
      one.history.fn_prev = uniform(0.0, 20.0);
      one.history.fd_prev = uniform(-2.0, 2.0);
      for (int d = 0; d < 3; ++d) one.history.ft[d] = uniform(-(c % 4 == 3 ? 50.0 : 1.0), c % 4 == 3 ? 50.0 : 1.0);
      for (int d = 0; d < 3; ++d) one.torque[d] = one.rolling ? uniform(-1e-3, 1e-3) : 0.0;
    }
  }
  dd::StepDissipation diss;
  for (int step = 0; step < steps; ++step) {
    for (std::size_t c = 0; c < kContacts; ++c) {
      dd::ContactKinematics& k = kin[c];
      unit(k.n);
      k.delta = uniform(1e-8, 2e-5);
      for (int d = 0; d < 3; ++d) k.v[d] = uniform(-2.0, 2.0);
      for (int d = 0; d < 3; ++d) k.w[d] = uniform(-300.0, 300.0);
    }
    evaluate_in_lanes<W>(contacts, kin, 1e-7, law, diss);
  }
  return {contacts, diss};
}

template <class W>
void check_lanes_against_scalar() {
  constexpr int kSteps = 20;
  const auto [scalar, scalar_diss] = random_contacts_in_lanes<dd::simd::Lanes1>(kSteps);
  const auto [lanes, lanes_diss] = random_contacts_in_lanes<W>(kSteps);
  int differing = 0;
  for (std::size_t c = 0; c < scalar.size(); ++c) {
    const auto& a = scalar[c];
    const auto& b = lanes[c];
    const bool same = same_bits(a.history.ft, b.history.ft, 3) && same_bits(&a.history.inv_kt_prev, &b.history.inv_kt_prev, 1) &&
                      same_bits(&a.history.gamma, &b.history.gamma, 1) && same_bits(&a.history.fd_prev, &b.history.fd_prev, 1) &&
                      same_bits(&a.history.fn_prev, &b.history.fn_prev, 1) && same_bits(a.torque, b.torque, 3) &&
                      same_bits(a.out.f, b.out.f, 3) && same_bits(a.out.c, b.out.c, 3) && same_bits(a.out.m, b.out.m, 3);
    if (!same) ++differing;
  }
  CHECK(differing == 0);
  CHECK(same_bits(&scalar_diss.normal_damping, &lanes_diss.normal_damping, 1));
  CHECK(same_bits(&scalar_diss.friction, &lanes_diss.friction, 1));
  CHECK(same_bits(&scalar_diss.rolling, &lanes_diss.rolling, 1));
  CHECK(scalar_diss.contacts == lanes_diss.contacts);
  // The random states did take the kernel's paths (else the check above proves little).
  CHECK(scalar_diss.friction > 0.0);
  CHECK(scalar_diss.rolling > 0.0);
}

}  // namespace

// Reference: the one-lane instantiation (the scalar kernel, pinned by the state hashes
// of test_world.cpp). The lanes run the same IEEE operations in the same order, so the
// histories, results and dissipation sums must be the same bits (tolerance: none).
TEST_CASE("the contact kernel in two, four or eight lanes gives the bits of the one-lane kernel", "[dem_reference]") {
  SECTION("two lanes in plain C++ (the portable fallback)") { check_lanes_against_scalar<dd::simd::LanesPortable2>(); }
  SECTION("two lanes of the build (SSE2, NEON or plain C++)") { check_lanes_against_scalar<dd::simd::Lanes2>(); }
#if defined(PDAMP_LANES_AVX2)
  SECTION("four AVX2 lanes") { check_lanes_against_scalar<dd::simd::LanesAvx2>(); }
#endif
#if defined(PDAMP_LANES_AVX512)
  SECTION("eight AVX-512 lanes") { check_lanes_against_scalar<dd::simd::LanesAvx512>(); }
#endif
}
