// Material-pair table of the reference DEM and the per-contact parameters.
#include "contact_law.hpp"

#include <algorithm>
#include <limits>

namespace pdamp::dem_reference::detail {

namespace {

/// One shared table: building it integrates the one-collision ODE on a grid.
const formulas::DampingTable& damping_table() {
  static const formulas::DampingTable table;
  return table;
}

const ContactPairOptions& pair_options(const WorldOptions& options, int a, int b) {
  for (const auto& pair : options.pairs) {
    if ((pair.material_a == a && pair.material_b == b) || (pair.material_a == b && pair.material_b == a)) {
      return pair;
    }
  }
  return options.default_pair;
}

std::shared_ptr<const formulas::RestitutionModel> restitution_model(const RestitutionOptions& r) {
  if (r.model) return r.model;
  if (!r.table_speeds_m_s.empty()) {
    return formulas::make_tabulated_restitution(r.table_speeds_m_s, r.table_values);
  }
  return formulas::make_constant_restitution(r.constant);
}

double shear_modulus(const formulas::Material& m) {
  return m.youngs_modulus_pa / (2.0 * (1.0 + m.poisson_ratio));
}

/// ContactParams::inv_radius_squared from K with the kernel's operations (√R* = K/((4/3)E*),
/// R* = √R*², 1/R*²), so that the stored value is the one the kernel formed every step.
double inverse_radius_squared(double stiffness, const PairType& type) {
  const double root_r = stiffness * type.inv_hertz_modulus;
  const double r_eff = root_r * root_r;
  return 1.0 / (r_eff * r_eff);
}

}  // namespace

ContactLaw::ContactLaw(const WorldOptions& options)
    : materials_(static_cast<int>(options.materials.size())) {
  const auto types = static_cast<std::size_t>(materials_ * materials_);
  e_star_.resize(types);
  types_.resize(types);
  restitution_.resize(types);
  constant_gamma_.resize(types);
  for (int a = 0; a < materials_; ++a) {
    for (int b = 0; b < materials_; ++b) {
      const auto t = static_cast<std::size_t>(pair_type(a, b));
      const auto& ma = options.materials[static_cast<std::size_t>(a)].material;
      const auto& mb = options.materials[static_cast<std::size_t>(b)].material;
      e_star_[t] = formulas::effective_modulus(ma, mb);
      // Mindlin: 1/G* = (2−ν₁)/G₁ + (2−ν₂)/G₂, k_t = 8G*a with a = √(R*δ).
      const double g_star = 1.0 / ((2.0 - ma.poisson_ratio) / shear_modulus(ma) +
                                   (2.0 - mb.poisson_ratio) / shear_modulus(mb));
      const auto& pair = pair_options(options, a, b);
      types_[t].tangential_ratio = 6.0 * g_star / e_star_[t];
      types_[t].friction = pair.friction;
      types_[t].rolling_friction = pair.rolling_friction;
      types_[t].inv_hertz_modulus = 0.75 / e_star_[t];
      restitution_[t] = restitution_model(pair.restitution);
      const bool constant = !pair.restitution.model && pair.restitution.table_speeds_m_s.empty();
      constant_gamma_[t] = constant ? formulas::damping_for_restitution(pair.restitution.constant)
                                    : std::numeric_limits<double>::quiet_NaN();
    }
  }
  // One layered law per (particle material, layer) of the compartments. The sphere's
  // radius does not enter the dimensionless law (R* = 1 m stands in).
  for (const auto& c : options.compartments) {
    if (!(c.layer.thickness_m > 0.0)) continue;
    const auto& layer = options.materials[static_cast<std::size_t>(c.layer.material)].material;
    for (const auto& group : c.particles) {
      const int type = pair_type(group.material, c.layer.material);
      const bool known = std::any_of(layers_.begin(), layers_.end(), [&](const WallLayerLaw& l) {
        return l.pair_type == type && l.thickness_m == c.layer.thickness_m;
      });
      if (known) continue;
      const auto& sphere = options.materials[static_cast<std::size_t>(group.material)].material;
      formulas::LayeredContact contact(1.0, layer.youngs_modulus_pa, layer.poisson_ratio, sphere.youngs_modulus_pa,
                                       sphere.poisson_ratio, c.layer.thickness_m);
      formulas::LayeredDampingTable damping(contact);
      layers_.push_back(WallLayerLaw{type, c.layer.thickness_m, 1.0 / c.layer.thickness_m, std::move(contact),
                                     std::move(damping)});
    }
  }
}

ContactParams ContactLaw::particle_pair(double radius_i, double mass_i, int material_i,
                                        double radius_j, double mass_j, int material_j) const {
  const int type = pair_type(material_i, material_j);
  const auto t = static_cast<std::size_t>(type);
  const double r_eff = radius_i * radius_j / (radius_i + radius_j);
  const double m_eff = mass_i * mass_j / (mass_i + mass_j);
  ContactParams p;
  p.stiffness = 4.0 / 3.0 * e_star_[t] * std::sqrt(r_eff);
  p.damping_scale = std::sqrt(m_eff * p.stiffness);
  p.pair_type = type;
  p.inv_radius_squared = inverse_radius_squared(p.stiffness, types_[t]);
  return p;
}

ContactParams ContactLaw::particle_wall(double radius_i, double mass_i, int material_i,
                                        int wall_material, double wall_radius_m, double layer_thickness_m) const {
  const int type = pair_type(material_i, wall_material);
  const auto t = static_cast<std::size_t>(type);
  // Curved walls: Hertz's equivalent radius √(R'R'') of the two principal relative
  // radii (R' = r along the wall's straight direction, R'' across it).
  double r_eff = radius_i;
  if (wall_radius_m > 0.0) {
    r_eff = std::sqrt(radius_i * radius_i * wall_radius_m / (radius_i + wall_radius_m));
  } else if (wall_radius_m < 0.0) {
    const double rc = -wall_radius_m;
    r_eff = std::sqrt(radius_i * radius_i * rc / (rc - radius_i));
  }
  ContactParams p;
  p.stiffness = 4.0 / 3.0 * e_star_[t] * std::sqrt(r_eff);
  p.damping_scale = std::sqrt(mass_i * p.stiffness);
  p.pair_type = type;
  p.inv_radius_squared = inverse_radius_squared(p.stiffness, types_[t]);
  if (layer_thickness_m > 0.0) {
    for (std::size_t l = 0; l < layers_.size(); ++l) {
      if (layers_[l].pair_type == type && layers_[l].thickness_m == layer_thickness_m) p.layer = static_cast<int>(l);
    }
    if (p.layer < 0) throw std::logic_error("ContactLaw: no law for this wall layer");
  }
  return p;
}

double ContactLaw::damping_coefficient(const ContactParams& params, double impact_speed_m_s) const {
  const auto t = static_cast<std::size_t>(params.pair_type);
  if (params.layer < 0 && !std::isnan(constant_gamma_[t])) return constant_gamma_[t];
  // Validation keeps ε(v) in the table's range [0.01, 1] up to max_impact_speed_m_s;
  // a faster first touch gets the nearest value of that range instead of an exception
  // that would end the run (0.01 and less are both practically plastic). Values inside
  // the range are unchanged, so are the results; NaN stays NaN and the table throws.
  const double restitution = std::clamp(restitution_[t]->restitution(impact_speed_m_s),
                                        formulas::DampingTable::kMinRestitution, 1.0);
  if (params.layer < 0) return damping_table().damping_for_restitution(restitution);
  // On a layer ε(γ_n) depends on the impact's overlap parameter ξ = √(R*δ_H)/t, with the
  // Hertz maximum overlap δ_H = (5m*v²/4K)^{2/5} (formulas::LayeredDampingTable).
  const WallLayerLaw& l = layers_[static_cast<std::size_t>(params.layer)];
  const double root_r = params.stiffness * types_[t].inv_hertz_modulus;
  const double mass = params.damping_scale * params.damping_scale / params.stiffness;
  const double hertz_overlap = std::pow(1.25 * mass * impact_speed_m_s * impact_speed_m_s / params.stiffness, 0.4);
  return l.damping.damping_for_restitution(root_r * std::sqrt(hertz_overlap) * l.inv_thickness, restitution);
}

bool ContactLaw::any_rolling_friction() const {
  return std::any_of(types_.begin(), types_.end(), [](const PairType& t) { return t.rolling_friction > 0.0; });
}

double stored_energy(const ContactParams& p, const ContactLaw& law, const ContactHistory& h, const double* mr,
                     double delta) {
  if (delta <= 0.0 || h.inv_kt_prev <= 0.0) return 0.0;
  const PairType& type = law.type(p.pair_type);
  const double hertz = 0.4 * p.stiffness * delta * delta * std::sqrt(delta) * law.hertz_ratios(p, std::sqrt(delta)).energy;
  const double ft2 = h.ft[0] * h.ft[0] + h.ft[1] * h.ft[1] + h.ft[2] * h.ft[2];
  double springs = 0.5 * ft2 * h.inv_kt_prev;
  if (type.rolling_friction > 0.0) {
    const double root_r = p.stiffness * type.inv_hertz_modulus;
    const double r2 = root_r * root_r * root_r * root_r;
    const double mr2 = mr[0] * mr[0] + mr[1] * mr[1] + mr[2] * mr[2];
    springs += 0.5 * mr2 * h.inv_kt_prev / r2;
  }
  return hertz + springs;
}

}  // namespace pdamp::dem_reference::detail
