// Planar Euler-Bernoulli frame elements along x (Hermite cubic bending + linear axial bar,
// consistent masses), gravity's geometric stiffness and the modal reduction of the beam.
// Model, conventions and limits: docs/structures.md, "Beam models".
#include "pdamp/structure/beam.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "pdamp/base/input_file.hpp"

namespace pdamp::structure {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr Eigen::Index kDofsPerNode = 3;
/// Positions closer than this fraction of the beam length share one node.
constexpr double kMergeFraction = 1e-9;
/// A feature (support, mass, point, carried weight) closer than this fraction of the
/// finest nominal element (segment length / elements) to another key position shares its
/// node: a sliver element of length s between them adds EI/s³ terms that dwarf the rest of
/// K (at s = 1e-5 of an element the eigensolver returned a negative ω²). The feature then
/// sits at most 1% of an element from where it was asked, which moves its shape by about
/// 1% of an element times the shape's slope.
constexpr double kSliverFraction = 1e-2;
/// A computed eigenvalue below −kNegativeEigenvalueFraction·λ_max is truly negative (an
/// unstable, buckled beam): the eigenvalues of L⁻¹KL⁻ᵀ (M = LLᵀ) carry an absolute
/// round-off of about ε·λ_max ≈ 2e-16·λ_max, so the zero eigenvalues of rigid modes stay
/// far inside this bound.
constexpr double kNegativeEigenvalueFraction = 1e-10;

using Matrix6d = Eigen::Matrix<double, 6, 6>;
/// Local DOFs of the bending part (w1, θ1, w2, θ2) inside an element's (u1, w1, θ1, u2, w2, θ2).
constexpr std::array<int, 4> kBendingDofs{1, 2, 4, 5};

using base::format_number;
using base::non_negative_finite;
using base::positive_finite;

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += (text.empty() ? "" : "; ") + line;
  return text;
}

void throw_if_any(const std::vector<std::string>& problems, const std::string& context) {
  if (!problems.empty()) throw std::invalid_argument(base::printable(context + ": " + joined(problems)));
}

bool within(double x, double lo, double hi) { return std::isfinite(x) && x >= lo && x <= hi; }
/// "must be in [lo, hi] unit".
std::string interval(double lo, double hi, const std::string& unit) {
  return "must be in [" + format_number(lo, 12) + ", " + format_number(hi, 12) + "] " + unit;
}

/// Adds "<field> = <value>: <rule>" unless `ok`.
void require(std::vector<std::string>& problems, bool ok, const std::string& field, double value,
             const std::string& rule) {
  if (!ok) problems.push_back(field + " = " + format_number(value, 12) + ": " + rule);
}

void section_problems(const Section& s, const std::string& at, std::vector<std::string>& problems) {
  const bool rectangle = s.shape == SectionShape::kSolidRectangle || s.shape == SectionShape::kHollowRectangle;
  const bool hollow = s.shape == SectionShape::kHollowRectangle || s.shape == SectionShape::kHollowCircle;
  if (rectangle) {
    for (const auto& [field, value] : {std::pair<const char*, double>{"width_m", s.width_m}, {"depth_m", s.depth_m}})
      require(problems, within(value, beam_limits::kMinSectionSize_m, beam_limits::kMaxSectionSize_m), at + field, value,
              interval(beam_limits::kMinSectionSize_m, beam_limits::kMaxSectionSize_m, "m"));
    require(problems, s.diameter_m == 0.0, at + "diameter_m", s.diameter_m, "rectangles have no diameter, must be 0");
  } else {
    require(problems, within(s.diameter_m, beam_limits::kMinSectionSize_m, beam_limits::kMaxSectionSize_m), at + "diameter_m",
            s.diameter_m, interval(beam_limits::kMinSectionSize_m, beam_limits::kMaxSectionSize_m, "m"));
    require(problems, s.width_m == 0.0, at + "width_m", s.width_m, "circles use diameter_m, must be 0");
    require(problems, s.depth_m == 0.0, at + "depth_m", s.depth_m, "circles use diameter_m, must be 0");
  }
  if (!hollow) {
    require(problems, s.wall_thickness_m == 0.0, at + "wall_thickness_m", s.wall_thickness_m,
            "solid sections have no wall, must be 0");
    return;
  }
  const double half_size = 0.5 * (rectangle ? std::min(s.width_m, s.depth_m) : s.diameter_m);
  require(problems, s.wall_thickness_m >= beam_limits::kMinSectionSize_m && s.wall_thickness_m < half_size,
          at + "wall_thickness_m", s.wall_thickness_m,
          "must be in [" + format_number(beam_limits::kMinSectionSize_m, 12) + ", " + format_number(half_size, 12) +
              ") m (half the smallest outer size)");
}

/// True if the support carries axial load (it fixes x or has an axial spring).
bool restrains_axially(const Support& support) {
  return support.kind != Support::Kind::kSpring || support.axial_stiffness_n_m > 0.0;
}

/// One two-node element between nodes `first_node` and `first_node + 1`.
struct Element {
  Eigen::Index first_node = 0;
  double length_m = 0.0;
  double axial_rigidity_n = 0.0;          ///< EA
  double bending_rigidity_n_m2 = 0.0;     ///< EI
  double mass_per_length_kg_m = 0.0;      ///< ρA
};

struct Mesh {
  std::vector<double> node_x_m;
  std::vector<Element> elements;
  double merge_tolerance_m = 0.0;

  Eigen::Index dofs() const { return kDofsPerNode * static_cast<Eigen::Index>(node_x_m.size()); }

  /// The node at x (nodes are placed at every support, point mass and named point).
  Eigen::Index node_at(double x) const {
    const auto it = std::lower_bound(node_x_m.begin(), node_x_m.end(), x - merge_tolerance_m);
    if (it == node_x_m.end() || std::abs(*it - x) > merge_tolerance_m) {
      throw std::logic_error("beam mesh: no node at x = " + format_number(x, 12) + " m");
    }
    return it - node_x_m.begin();
  }
  /// The element holding x and the local coordinate ξ = (x − x_start)/l in [0, 1].
  std::pair<const Element*, double> element_at(double x) const {
    for (const Element& e : elements) {
      const double start = node_x_m[static_cast<std::size_t>(e.first_node)];
      if (x <= start + e.length_m || &e == &elements.back()) {
        return {&e, std::clamp((x - start) / e.length_m, 0.0, 1.0)};
      }
    }
    throw std::logic_error("beam mesh: no elements");
  }
};

/// Nodes at every segment boundary, support, point mass and named point. Segment
/// boundaries stay where they are; a feature within the merge tolerance (the larger of
/// kMergeFraction·L and kSliverFraction of the finest nominal element) of a key already
/// placed shares its node. Each piece between two keys gets its segment's element count in
/// proportion to its length (at least one), so no sliver elements appear.
Mesh build_mesh(const BeamModel& beam) {
  const double length = beam.length_m();
  Mesh mesh;
  double finest_element_m = length;
  for (const auto& segment : beam.segments)
    finest_element_m = std::min(finest_element_m, segment.length_m / std::max(1, segment.elements));
  mesh.merge_tolerance_m = std::max(kMergeFraction * length, kSliverFraction * finest_element_m);

  std::vector<double> segment_end_m;
  std::vector<double> keys{0.0};
  double end = 0.0;
  for (const auto& segment : beam.segments) {
    end += segment.length_m;
    segment_end_m.push_back(end);
    keys.push_back(end);
  }
  std::vector<double> features;
  const auto add_feature = [&](double x) { features.push_back(std::clamp(x, 0.0, length)); };
  for (const auto& s : beam.supports) add_feature(s.position_m);
  for (const auto& m : beam.point_masses) add_feature(m.position_m);
  for (const auto& p : beam.points) add_feature(p.position_m);
  for (const auto& w : beam.carried_weights) add_feature(w.position_m);
  std::sort(features.begin(), features.end());
  for (double x : features) {
    const auto it = std::lower_bound(keys.begin(), keys.end(), x);
    const bool near_next = it != keys.end() && *it - x <= mesh.merge_tolerance_m;
    const bool near_previous = it != keys.begin() && x - *(it - 1) <= mesh.merge_tolerance_m;
    if (!near_next && !near_previous) keys.insert(it, x);
  }

  mesh.node_x_m.push_back(keys.front());
  for (std::size_t k = 0; k + 1 < keys.size(); ++k) {
    const double a = keys[k];
    const double b = keys[k + 1];
    const double middle = 0.5 * (a + b);
    std::size_t s = 0;
    while (s + 1 < beam.segments.size() && middle > segment_end_m[s]) ++s;
    const BeamSegment& segment = beam.segments[s];
    const long pieces = std::max(1L, std::lround(segment.elements * (b - a) / segment.length_m));
    Element element;
    element.axial_rigidity_n = segment.material.youngs_modulus_pa * segment.section.area_m2();
    element.bending_rigidity_n_m2 = segment.material.youngs_modulus_pa * segment.section.second_moment_m4();
    element.mass_per_length_kg_m = segment.material.density_kg_m3 * segment.section.area_m2();
    for (long i = 1; i <= pieces; ++i) {
      const double x = i == pieces ? b : a + (b - a) * static_cast<double>(i) / static_cast<double>(pieces);
      element.first_node = static_cast<Eigen::Index>(mesh.node_x_m.size()) - 1;
      element.length_m = x - mesh.node_x_m.back();
      mesh.elements.push_back(element);
      mesh.node_x_m.push_back(x);
    }
  }
  return mesh;
}

/// Element stiffness in (u1, w1, θ1, u2, w2, θ2): the bar EA/l [1 −1; −1 1] and the
/// Hermite cubic bending matrix EI/l³ [12 6l −12 6l; ...] (Przemieniecki 1968, eq. 5.24;
/// Cook et al. 2002, eq. 2.3-5).
Matrix6d element_stiffness(const Element& e) {
  const double l = e.length_m;
  Matrix6d k = Matrix6d::Zero();
  const double bar = e.axial_rigidity_n / l;
  k(0, 0) = k(3, 3) = bar;
  k(0, 3) = k(3, 0) = -bar;
  const double b = e.bending_rigidity_n_m2 / (l * l * l);
  const double bending[4][4] = {{12.0, 6.0 * l, -12.0, 6.0 * l},
                                {6.0 * l, 4.0 * l * l, -6.0 * l, 2.0 * l * l},
                                {-12.0, -6.0 * l, 12.0, -6.0 * l},
                                {6.0 * l, 2.0 * l * l, -6.0 * l, 4.0 * l * l}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) k(kBendingDofs[i], kBendingDofs[j]) = b * bending[i][j];
  return k;
}

/// Consistent element mass (same interpolation as the stiffness): bar ρAl/6 [2 1; 1 2],
/// bending ρAl/420 [156 22l 54 −13l; ...] (Przemieniecki 1968, eq. 11.41). Plain
/// Euler-Bernoulli: the rotary inertia of the section itself is left out.
Matrix6d element_mass(const Element& e) {
  const double l = e.length_m;
  const double m = e.mass_per_length_kg_m * l;
  Matrix6d mass = Matrix6d::Zero();
  mass(0, 0) = mass(3, 3) = m / 3.0;
  mass(0, 3) = mass(3, 0) = m / 6.0;
  const double bending[4][4] = {{156.0, 22.0 * l, 54.0, -13.0 * l},
                                {22.0 * l, 4.0 * l * l, 13.0 * l, -3.0 * l * l},
                                {54.0, 13.0 * l, 156.0, -22.0 * l},
                                {-13.0 * l, -3.0 * l * l, -22.0 * l, 4.0 * l * l}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) mass(kBendingDofs[i], kBendingDofs[j]) = m / 420.0 * bending[i][j];
  return mass;
}

/// Hermite cubics at ξ = x/l: values (w1, θ1, w2, θ2) and their x-derivatives.
struct HermiteAt {
  Eigen::Vector4d value;
  Eigen::Vector4d slope;
};
HermiteAt hermite(double xi, double l) {
  HermiteAt h;
  h.value << 1.0 - 3.0 * xi * xi + 2.0 * xi * xi * xi, l * (xi - 2.0 * xi * xi + xi * xi * xi),
      3.0 * xi * xi - 2.0 * xi * xi * xi, l * (-xi * xi + xi * xi * xi);
  h.slope << (-6.0 * xi + 6.0 * xi * xi) / l, 1.0 - 4.0 * xi + 3.0 * xi * xi, (6.0 * xi - 6.0 * xi * xi) / l,
      -2.0 * xi + 3.0 * xi * xi;
  return h;
}

/// Geometric stiffness ∫ N(x) H'ᵀH' dx of an axial force varying linearly from
/// `tension_start_n` to `tension_end_n` (tension > 0). The integrand is a degree-5
/// polynomial, so 3-point Gauss is exact; for constant N it is the standard
/// N/(30l) [36 3l −36 3l; 3l 4l² −3l −l²; ...] (Przemieniecki 1968, eq. 15.12; Cook et al. §18.2).
Matrix6d element_geometric_stiffness(const Element& e, double tension_start_n, double tension_end_n) {
  const double l = e.length_m;
  const std::array<double, 3> xi{0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  const std::array<double, 3> weight{5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  Eigen::Matrix4d bending = Eigen::Matrix4d::Zero();
  for (int g = 0; g < 3; ++g) {
    const double tension = tension_start_n + (tension_end_n - tension_start_n) * xi[g];
    const Eigen::Vector4d slope = hermite(xi[g], l).slope;
    bending += weight[g] * l * tension * slope * slope.transpose();
  }
  Matrix6d k = Matrix6d::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) k(kBendingDofs[i], kBendingDofs[j]) = bending(i, j);
  return k;
}

/// Axial tension (N, > 0 in tension) at the start and end of every element from gravity
/// along x. The axial load is statically indeterminate when several supports hold x, so
/// we assume it all goes to the axially restraining support nearest x = 0 (the anchor):
/// beyond the anchor N(x) = g_x·(mass beyond x), before it N(x) = −g_x·(mass before x).
std::vector<std::pair<double, double>> gravity_tension(const BeamModel& beam, const Mesh& mesh) {
  const Support* anchor = nullptr;
  for (const auto& s : beam.supports) {
    if (restrains_axially(s) && (anchor == nullptr || s.position_m < anchor->position_m)) anchor = &s;
  }
  const Eigen::Index anchor_node = mesh.node_at(std::clamp(anchor->position_m, 0.0, beam.length_m()));

  const std::size_t nodes = mesh.node_x_m.size();
  std::vector<double> point_mass_kg(nodes, 0.0);
  for (const auto& m : beam.point_masses) {
    const Eigen::Index node = mesh.node_at(std::clamp(m.position_m, 0.0, beam.length_m()));
    point_mass_kg[static_cast<std::size_t>(node)] += m.mass_kg;
  }
  for (const auto& w : beam.carried_weights) {
    const Eigen::Index node = mesh.node_at(std::clamp(w.position_m, 0.0, beam.length_m()));
    point_mass_kg[static_cast<std::size_t>(node)] += w.mass_kg;
  }
  // distributed_before[i]: beam mass on [0, x_i]; point_before[i]: point masses at nodes < i.
  std::vector<double> distributed_before(nodes, 0.0);
  std::vector<double> point_before(nodes + 1, 0.0);
  for (const Element& e : mesh.elements) {
    const auto i = static_cast<std::size_t>(e.first_node);
    distributed_before[i + 1] = distributed_before[i] + e.mass_per_length_kg_m * e.length_m;
  }
  for (std::size_t i = 0; i < nodes; ++i) point_before[i + 1] = point_before[i] + point_mass_kg[i];
  const double distributed_total = distributed_before.back();
  const double point_total = point_before.back();

  const double g = beam.axial_gravity_m_s2;
  std::vector<std::pair<double, double>> tension;
  for (const Element& e : mesh.elements) {
    const auto a = static_cast<std::size_t>(e.first_node);
    if (e.first_node >= anchor_node) {
      const double points_beyond = point_total - point_before[a + 1];  // at nodes >= a + 1
      tension.emplace_back(g * (distributed_total - distributed_before[a] + points_beyond),
                           g * (distributed_total - distributed_before[a + 1] + points_beyond));
    } else {
      const double points_before = point_before[a + 1];  // at nodes <= a
      tension.emplace_back(-g * (distributed_before[a] + points_before),
                           -g * (distributed_before[a + 1] + points_before));
    }
  }
  return tension;
}

struct Assembly {
  Mesh mesh;
  BeamMatrices matrices;
  std::vector<Eigen::Index> free_dofs;
  int rigid_modes = 0;
  bool has_geometric_stiffness = false;
};

/// Number of rigid-body modes: the dimension of the rigid motions a = (a_x, a_y, a_θ)
/// (u = a_x, w = a_y + a_θ x, θ = a_θ) that no support, spring or axial force resists.
/// The elastic stiffness of a connected beam (EA, EI > 0) has exactly these motions as
/// its null space, so the count is exact, with no threshold on computed eigenvalues.
/// Each constraint is a row c with c·a = 0 (rotation scaled by L to keep rows O(1)); a
/// net axial force resists the rigid rotation (energy ½a_θ²∫N dx: a hanging pendulum).
int rigid_body_modes(const BeamModel& beam, const Mesh& mesh, double tension_integral_n_m) {
  const double length = beam.length_m();
  std::vector<Eigen::RowVector3d> constraints;
  const auto add = [&](bool active, const Eigen::RowVector3d& row) {
    if (active) constraints.push_back(row.normalized());
  };
  for (const auto& s : beam.supports) {
    const double x = mesh.node_x_m[static_cast<std::size_t>(mesh.node_at(std::clamp(s.position_m, 0.0, length)))];
    const bool spring = s.kind == Support::Kind::kSpring;
    add(!spring || s.axial_stiffness_n_m > 0.0, {1.0, 0.0, 0.0});
    add(!spring || s.transverse_stiffness_n_m > 0.0, {0.0, 1.0, x / length});
    add(s.kind == Support::Kind::kClamped || (spring && s.rotational_stiffness_n_m_rad > 0.0), {0.0, 0.0, 1.0});
  }
  add(tension_integral_n_m != 0.0, {0.0, 0.0, 1.0});
  if (constraints.empty()) return 3;
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(constraints.size()), 3);
  for (std::size_t i = 0; i < constraints.size(); ++i) rows.row(static_cast<Eigen::Index>(i)) = constraints[i];
  // Unit rows: singular values are O(1) or round-off, 1e-9 separates them safely.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(rows);
  const auto& sigma = svd.singularValues();
  return 3 - static_cast<int>((sigma.array() > 1e-9 * sigma[0]).count());
}

Assembly assemble(const BeamModel& beam) {
  throw_if_any(beam.validate(), "beam model");
  Assembly a;
  a.mesh = build_mesh(beam);
  const Mesh& mesh = a.mesh;
  const Eigen::Index dofs = mesh.dofs();
  BeamMatrices& m = a.matrices;
  m.node_positions_m = Eigen::Map<const Eigen::VectorXd>(mesh.node_x_m.data(), static_cast<Eigen::Index>(mesh.node_x_m.size()));
  m.mass_kg = Eigen::MatrixXd::Zero(dofs, dofs);
  m.stiffness_n_m = Eigen::MatrixXd::Zero(dofs, dofs);

  // Consecutive nodes: an element's 6 DOFs are one contiguous block of the global matrices.
  for (const Element& e : mesh.elements) {
    const Eigen::Index first = kDofsPerNode * e.first_node;
    m.stiffness_n_m.block<6, 6>(first, first) += element_stiffness(e);
    m.mass_kg.block<6, 6>(first, first) += element_mass(e);
  }
  double tension_integral_n_m = 0.0;  // ∫N dx
  a.has_geometric_stiffness = beam.geometric_stiffness && beam.axial_gravity_m_s2 != 0.0;
  if (a.has_geometric_stiffness) {
    const auto tension = gravity_tension(beam, mesh);
    for (std::size_t i = 0; i < mesh.elements.size(); ++i) {
      const Element& e = mesh.elements[i];
      const Eigen::Index first = kDofsPerNode * e.first_node;
      m.stiffness_n_m.block<6, 6>(first, first) += element_geometric_stiffness(e, tension[i].first, tension[i].second);
      tension_integral_n_m += 0.5 * (tension[i].first + tension[i].second) * e.length_m;
    }
  }
  a.rigid_modes = rigid_body_modes(beam, mesh, tension_integral_n_m);

  const auto node_of = [&](double x) { return mesh.node_at(std::clamp(x, 0.0, beam.length_m())); };
  for (const auto& pm : beam.point_masses) {
    const Eigen::Index first = kDofsPerNode * node_of(pm.position_m);
    m.mass_kg(first, first) += pm.mass_kg;
    m.mass_kg(first + 1, first + 1) += pm.mass_kg;
    m.mass_kg(first + 2, first + 2) += pm.rotary_inertia_kg_m2;
  }

  std::set<Eigen::Index> fixed;
  for (const auto& s : beam.supports) {
    const Eigen::Index first = kDofsPerNode * node_of(s.position_m);
    switch (s.kind) {
      case Support::Kind::kClamped:
        fixed.insert({first, first + 1, first + 2});
        break;
      case Support::Kind::kPinned:
        fixed.insert({first, first + 1});
        break;
      case Support::Kind::kSpring:
        m.stiffness_n_m(first, first) += s.axial_stiffness_n_m;
        m.stiffness_n_m(first + 1, first + 1) += s.transverse_stiffness_n_m;
        m.stiffness_n_m(first + 2, first + 2) += s.rotational_stiffness_n_m_rad;
        break;
    }
  }
  m.fixed_dofs.assign(fixed.begin(), fixed.end());
  for (Eigen::Index dof = 0; dof < dofs; ++dof) {
    if (fixed.count(dof) == 0) a.free_dofs.push_back(dof);
  }
  return a;
}

/// Elastic modes over the free DOFs: ω² ascending, M_ff-orthonormal vectors.
struct FreeVibration {
  Eigen::VectorXd eigenvalues_rad2_s2;
  Eigen::MatrixXd vectors;  ///< free DOFs x elastic modes
};

FreeVibration free_vibration(const Assembly& a) {
  const auto& free = a.free_dofs;
  if (free.empty()) throw std::invalid_argument("beam model: the supports fix every DOF, there is no mode");
  const Eigen::MatrixXd stiffness = a.matrices.stiffness_n_m(free, free);
  const Eigen::MatrixXd mass = a.matrices.mass_kg(free, free);
  // K φ = ω² M φ with M positive definite (consistent masses, ρA > 0): Eigen factors
  // M = LLᵀ and returns vectors with φᵀMφ = 1.
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      stiffness, mass, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (solver.info() != Eigen::Success) {
    throw base::NumericalError("beam model: the generalized eigenproblem failed (mass matrix not positive definite?)");
  }
  const Eigen::VectorXd& lambda = solver.eigenvalues();  // ascending
  const Eigen::Index rigid = a.rigid_modes;
  if (rigid >= lambda.size()) throw std::invalid_argument("beam model: no elastic mode (every mode is a rigid-body mode)");
  if (!(lambda[rigid] > 0.0) || lambda[0] < -kNegativeEigenvalueFraction * lambda.maxCoeff()) {
    // Only the geometric stiffness of a compressive force makes K indefinite; otherwise a
    // stiffness so small that round-off swamps it (springs of 1e-20 N/m) ends up here.
    throw std::invalid_argument(
        a.has_geometric_stiffness
            ? "beam model: the axial compression from gravity exceeds the buckling load (lowest ω² = " +
                  format_number(lambda[0], 12) + " rad²/s²): the beam is unstable"
            : "beam model: an elastic mode has ω² = " + format_number(lambda[rigid], 12) +
                  " rad²/s² <= 0 (stiffnesses too disparate to resolve; soften the stiff parts or stiffen the soft "
                  "ones)");
  }
  FreeVibration result;
  const Eigen::Index elastic = lambda.size() - rigid;
  result.eigenvalues_rad2_s2 = lambda.tail(elastic);
  result.vectors = solver.eigenvectors().rightCols(elastic);
  return result;
}

/// Deterministic sign of a mode: its largest translation (u or w) is positive; among
/// translations within 1e-6 of the largest (symmetric modes), the one farthest along +x
/// decides, so round-off cannot flip the sign. A mode without translation uses θ.
void fix_sign(Eigen::Ref<Eigen::VectorXd> mode) {
  const Eigen::Index nodes = mode.size() / kDofsPerNode;
  double largest = 0.0;
  for (Eigen::Index i = 0; i < nodes; ++i) {
    largest = std::max({largest, std::abs(mode[kDofsPerNode * i]), std::abs(mode[kDofsPerNode * i + 1])});
  }
  const bool use_rotation = largest == 0.0;
  if (use_rotation) largest = mode.cwiseAbs().maxCoeff();
  for (Eigen::Index dof = mode.size() - 1; dof >= 0; --dof) {
    if (!use_rotation && dof % kDofsPerNode == 2) continue;
    if (std::abs(mode[dof]) >= (1.0 - 1e-6) * largest) {
      if (mode[dof] < 0.0) mode = -mode;
      return;
    }
  }
}

PointModeShape shape_at(const std::string& name, Eigen::Index node, const Eigen::MatrixXd& modes) {
  PointModeShape shape;
  shape.name = name;
  shape.translation = modes.middleRows(kDofsPerNode * node, 2);
  shape.rotation = modes.row(kDofsPerNode * node + 2);
  return shape;
}

}  // namespace

double Section::area_m2() const {
  switch (shape) {
    case SectionShape::kSolidRectangle:
      return width_m * depth_m;
    case SectionShape::kHollowRectangle:
      return width_m * depth_m - (width_m - 2.0 * wall_thickness_m) * (depth_m - 2.0 * wall_thickness_m);
    case SectionShape::kSolidCircle:
      return 0.25 * kPi * diameter_m * diameter_m;
    case SectionShape::kHollowCircle: {
      const double inner = diameter_m - 2.0 * wall_thickness_m;
      return 0.25 * kPi * (diameter_m * diameter_m - inner * inner);
    }
  }
  throw std::invalid_argument("section: unknown shape");
}

double Section::second_moment_m4() const {
  // About the z axis through the centroid: b d³/12 for a rectangle of in-plane depth d,
  // π D⁴/64 for a circle; hollow sections subtract the hole.
  switch (shape) {
    case SectionShape::kSolidRectangle:
      return width_m * std::pow(depth_m, 3) / 12.0;
    case SectionShape::kHollowRectangle:
      return (width_m * std::pow(depth_m, 3) -
              (width_m - 2.0 * wall_thickness_m) * std::pow(depth_m - 2.0 * wall_thickness_m, 3)) /
             12.0;
    case SectionShape::kSolidCircle:
      return kPi * std::pow(diameter_m, 4) / 64.0;
    case SectionShape::kHollowCircle:
      return kPi * (std::pow(diameter_m, 4) - std::pow(diameter_m - 2.0 * wall_thickness_m, 4)) / 64.0;
  }
  throw std::invalid_argument("section: unknown shape");
}

double BeamModel::length_m() const {
  double length = 0.0;
  for (const auto& segment : segments) length += segment.length_m;
  return length;
}

std::vector<std::string> BeamModel::validate() const {
  std::vector<std::string> problems;
  if (segments.empty()) problems.emplace_back("segments is empty: a beam needs at least one segment");
  const auto count_at_most = [&](std::size_t count, std::size_t max, const std::string& field) {
    if (count > max) problems.push_back(field + " has " + std::to_string(count) + " entries: at most " + std::to_string(max));
  };
  count_at_most(segments.size(), beam_limits::kMaxSegments, "segments");
  count_at_most(supports.size(), beam_limits::kMaxSupports, "supports");
  count_at_most(point_masses.size(), beam_limits::kMaxPoints, "point_masses");
  count_at_most(points.size(), beam_limits::kMaxPoints, "points");
  if (!problems.empty()) return problems;  // a hostile length is not walked
  long total_elements = 0;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const BeamSegment& s = segments[i];
    const std::string at = "segments/" + std::to_string(i) + "/";
    require(problems, within(s.length_m, beam_limits::kMinSegmentLength_m, beam_limits::kMaxSegmentLength_m),
            at + "length_m", s.length_m,
            interval(beam_limits::kMinSegmentLength_m, beam_limits::kMaxSegmentLength_m, "m"));
    require(problems, s.elements >= 1 && s.elements <= beam_limits::kMaxElements, at + "elements", s.elements,
            "must be in [1, " + std::to_string(beam_limits::kMaxElements) + "]");
    total_elements += std::max(s.elements, 0);
    require(problems, positive_finite(s.material.youngs_modulus_pa), at + "material/youngs_modulus_pa",
            s.material.youngs_modulus_pa, "must be > 0 Pa");
    require(problems, positive_finite(s.material.density_kg_m3), at + "material/density_kg_m3",
            s.material.density_kg_m3, "must be > 0 kg/m³");
    section_problems(s.section, at + "section/", problems);
  }
  if (total_elements > beam_limits::kMaxElements)
    problems.push_back("segments: " + std::to_string(total_elements) + " elements in all: at most " +
                       std::to_string(beam_limits::kMaxElements) + " (the modal eigenproblem is dense: O(n^3) work)");
  const double length = length_m();
  const double tolerance = kMergeFraction * length;
  const std::string position_rule = "must be in [0, " + format_number(length, 12) + "] m (on the beam)";
  const auto on_beam = [&](double x) { return std::isfinite(x) && x >= -tolerance && x <= length + tolerance; };

  bool axial_anchor = false;
  for (std::size_t i = 0; i < supports.size(); ++i) {
    const Support& s = supports[i];
    const std::string at = "supports/" + std::to_string(i) + "/";
    require(problems, on_beam(s.position_m), at + "position_m", s.position_m, position_rule);
    const std::array<std::pair<const char*, double>, 3> springs{
        {{"axial_stiffness_n_m", s.axial_stiffness_n_m},
         {"transverse_stiffness_n_m", s.transverse_stiffness_n_m},
         {"rotational_stiffness_n_m_rad", s.rotational_stiffness_n_m_rad}}};
    for (const auto& [field, value] : springs) {
      if (s.kind == Support::Kind::kSpring) {
        require(problems, within(value, 0.0, beam_limits::kMaxStiffness), at + field, value,
                interval(0.0, beam_limits::kMaxStiffness, ""));
      } else {
        require(problems, value == 0.0, at + field, value, "only spring supports take stiffnesses, must be 0");
      }
    }
    axial_anchor = axial_anchor || restrains_axially(s);
  }

  std::set<std::string> names;
  const auto check_name = [&](const std::string& name, const std::string& at) {
    if (name.empty()) problems.push_back(at + "name is empty: shapes are reported by name");
    if (!names.insert(name).second) {
      problems.push_back(at + "name = \"" + name + "\": must be unique among point masses and named points");
    }
  };
  for (std::size_t i = 0; i < point_masses.size(); ++i) {
    const PointMass& m = point_masses[i];
    const std::string at = "point_masses/" + std::to_string(i) + "/";
    check_name(m.name, at);
    require(problems, on_beam(m.position_m), at + "position_m", m.position_m, position_rule);
    require(problems, within(m.mass_kg, 0.0, beam_limits::kMaxPointMass_kg), at + "mass_kg", m.mass_kg,
            interval(0.0, beam_limits::kMaxPointMass_kg, "kg"));
    require(problems, within(m.rotary_inertia_kg_m2, 0.0, beam_limits::kMaxRotaryInertia_kg_m2), at + "rotary_inertia_kg_m2",
            m.rotary_inertia_kg_m2, interval(0.0, beam_limits::kMaxRotaryInertia_kg_m2, "kg m²"));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string at = "points/" + std::to_string(i) + "/";
    check_name(points[i].name, at);
    require(problems, on_beam(points[i].position_m), at + "position_m", points[i].position_m, position_rule);
  }
  for (std::size_t i = 0; i < carried_weights.size(); ++i) {
    const std::string at = "carried_weights/" + std::to_string(i) + "/";
    require(problems, on_beam(carried_weights[i].position_m), at + "position_m", carried_weights[i].position_m,
            position_rule);
    require(problems, non_negative_finite(carried_weights[i].mass_kg), at + "mass_kg", carried_weights[i].mass_kg,
            "must be >= 0 kg and finite");
  }
  require(problems, std::isfinite(axial_gravity_m_s2), "axial_gravity_m_s2", axial_gravity_m_s2, "must be finite");
  if (geometric_stiffness && axial_gravity_m_s2 != 0.0 && !axial_anchor) {
    problems.emplace_back(
        "geometric_stiffness = true: the axial load from gravity needs a support that holds x "
        "(clamped, pinned, or spring with axial_stiffness_n_m > 0)");
  }
  return problems;
}

std::vector<std::string> ModalDamping::validate() const {
  std::vector<std::string> problems;
  const bool rayleigh = rayleigh_alpha_1_s.has_value() || rayleigh_beta_s.has_value();
  if (!rayleigh && ratios.empty()) problems.emplace_back("ratios is empty: give one ratio at least, or Rayleigh terms");
  for (std::size_t j = 0; j < ratios.size(); ++j) {
    require(problems, within(ratios[j], 0.0, beam_limits::kMaxDampingRatio), "ratios/" + std::to_string(j), ratios[j],
            interval(0.0, beam_limits::kMaxDampingRatio, "(a vibration mode's damping ratio)"));
  }
  if (rayleigh_alpha_1_s) {
    require(problems, within(*rayleigh_alpha_1_s, 0.0, beam_limits::kMaxRayleighAlpha_1_s), "rayleigh_alpha_1_s",
            *rayleigh_alpha_1_s, interval(0.0, beam_limits::kMaxRayleighAlpha_1_s, "1/s"));
  }
  if (rayleigh_beta_s) {
    require(problems, within(*rayleigh_beta_s, 0.0, beam_limits::kMaxRayleighBeta_s), "rayleigh_beta_s", *rayleigh_beta_s,
            interval(0.0, beam_limits::kMaxRayleighBeta_s, "s"));
  }
  return problems;
}

BeamMatrices beam_matrices(const BeamModel& beam) { return assemble(beam).matrices; }

BeamModalResult beam_modal_model(const BeamModel& beam, int mode_count, const ModalDamping& damping) {
  throw_if_any(damping.validate(), "modal damping");
  if (mode_count < 1) throw std::invalid_argument("beam modal model: mode_count = " + std::to_string(mode_count) + ": must be >= 1");
  const Assembly a = assemble(beam);
  const FreeVibration vibration = free_vibration(a);
  if (vibration.eigenvalues_rad2_s2.size() < mode_count) {
    throw std::invalid_argument("beam modal model: mode_count = " + std::to_string(mode_count) + ": the model has only " +
                                std::to_string(vibration.eigenvalues_rad2_s2.size()) + " elastic modes (refine the mesh)");
  }

  const Eigen::Index dofs = a.mesh.dofs();
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(dofs, mode_count);
  modes(a.free_dofs, Eigen::all) = vibration.vectors.leftCols(mode_count);  // fixed DOFs stay 0
  for (Eigen::Index j = 0; j < mode_count; ++j) fix_sign(modes.col(j));

  BeamModalResult result;
  result.rigid_modes_dropped = a.rigid_modes;
  ModalModel& modal = result.modal;
  const Eigen::VectorXd omega = vibration.eigenvalues_rad2_s2.head(mode_count).cwiseSqrt();
  modal.natural_frequencies_hz = omega / (2.0 * kPi);
  modal.modal_masses_kg = Eigen::VectorXd::Ones(mode_count);
  modal.damping_ratios.resize(mode_count);
  const bool rayleigh = damping.rayleigh_alpha_1_s.has_value() || damping.rayleigh_beta_s.has_value();
  for (Eigen::Index j = 0; j < mode_count; ++j) {
    if (rayleigh) {
      // C = αM + βK is diagonal in mass-normalised modes: 2ζω = α + βω².
      modal.damping_ratios[j] = damping.rayleigh_alpha_1_s.value_or(0.0) / (2.0 * omega[j]) +
                                damping.rayleigh_beta_s.value_or(0.0) * omega[j] / 2.0;
    } else {
      modal.damping_ratios[j] = damping.ratios[std::min(static_cast<std::size_t>(j), damping.ratios.size() - 1)];
    }
  }

  const auto node_of = [&](double x) { return a.mesh.node_at(std::clamp(x, 0.0, beam.length_m())); };
  for (const auto& p : beam.points) modal.points.push_back(shape_at(p.name, node_of(p.position_m), modes));
  for (const auto& m : beam.point_masses) modal.points.push_back(shape_at(m.name, node_of(m.position_m), modes));

  // Base motion: every support (springs included) moves with the base by a rigid
  // translation r; the relative coordinates then feel −M r ü_base, and Γ = Φᵀ M r.
  Eigen::MatrixXd rigid_translation = Eigen::MatrixXd::Zero(dofs, 2);
  for (Eigen::Index node = 0; node < dofs / kDofsPerNode; ++node) {
    rigid_translation(kDofsPerNode * node, 0) = 1.0;
    rigid_translation(kDofsPerNode * node + 1, 1) = 1.0;
  }
  modal.base_participation = modes.transpose() * a.matrices.mass_kg * rigid_translation;
  modal.mode_shapes = std::move(modes);
  return result;
}

PointModeShape beam_point_shape(const BeamModel& beam, const ModalModel& modal, const std::string& name,
                                double position_m) {
  throw_if_any(beam.validate(), "beam point shape: beam model");
  const Mesh mesh = build_mesh(beam);
  if (modal.mode_shapes.rows() != mesh.dofs())
    throw std::invalid_argument("beam point shape: modal.mode_shapes has " + std::to_string(modal.mode_shapes.rows()) +
                                " rows, the beam has " + std::to_string(mesh.dofs()) +
                                " DOFs: pass the modal model of this beam");
  const double length = beam.length_m();
  if (!std::isfinite(position_m) || position_m < -kMergeFraction * length || position_m > (1.0 + kMergeFraction) * length)
    throw std::invalid_argument("beam point shape: position_m = " + format_number(position_m, 12) +
                                ": must be in [0, " + format_number(length, 12) + "] m");
  const auto [element, xi] = mesh.element_at(std::clamp(position_m, 0.0, length));
  const HermiteAt h = hermite(xi, element->length_m);
  const Eigen::Index first = kDofsPerNode * element->first_node;
  const Eigen::MatrixXd& modes = modal.mode_shapes;
  PointModeShape shape;
  shape.name = name;
  shape.translation = Eigen::MatrixXd::Zero(2, modes.cols());
  shape.rotation = Eigen::RowVectorXd::Zero(modes.cols());
  shape.translation.row(0) = (1.0 - xi) * modes.row(first) + xi * modes.row(first + kDofsPerNode);
  for (int i = 0; i < 4; ++i) {
    shape.translation.row(1) += h.value[i] * modes.row(first + kBendingDofs[i]);
    shape.rotation += h.slope[i] * modes.row(first + kBendingDofs[i]);
  }
  return shape;
}

Eigen::VectorXd static_deflection_modal_amplitudes(const BeamModel& beam, const ModalModel& modal,
                                                   double position_m, const Eigen::Vector2d& force_n,
                                                   double moment_n_m) {
  throw_if_any(modal.validate(), "static deflection: modal model");
  const Assembly a = assemble(beam);
  const Eigen::Index dofs = a.mesh.dofs();
  if (modal.mode_shapes.rows() != dofs) {
    throw std::invalid_argument("static deflection: modal.mode_shapes has " + std::to_string(modal.mode_shapes.rows()) +
                                " rows, the beam has " + std::to_string(dofs) +
                                " DOFs: pass the modal model of this beam");
  }
  const double length = beam.length_m();
  if (!std::isfinite(position_m) || position_m < -kMergeFraction * length || position_m > (1.0 + kMergeFraction) * length) {
    throw std::invalid_argument("static deflection: position_m = " + format_number(position_m, 12) +
                                ": must be in [0, " + format_number(length, 12) + "] m");
  }
  if (!force_n.allFinite() || !std::isfinite(moment_n_m)) {
    throw std::invalid_argument("static deflection: force and moment must be finite");
  }
  if (a.rigid_modes > 0) {
    throw std::invalid_argument("static deflection: the beam is a mechanism (" + std::to_string(a.rigid_modes) +
                                " rigid-body modes), a static load has no unique deflection");
  }

  // Consistent load vector (virtual work of the point load through the element's shape
  // functions): exact nodal values for Euler-Bernoulli elements, wherever the load sits.
  const auto [element, xi] = a.mesh.element_at(std::clamp(position_m, 0.0, length));
  const HermiteAt h = hermite(xi, element->length_m);
  Eigen::VectorXd load = Eigen::VectorXd::Zero(dofs);
  const Eigen::Index first = kDofsPerNode * element->first_node;
  load[first] += (1.0 - xi) * force_n.x();
  load[first + kDofsPerNode] += xi * force_n.x();
  for (int i = 0; i < 4; ++i) {
    load[first + kBendingDofs[i]] += h.value[i] * force_n.y() + h.slope[i] * moment_n_m;
  }

  const auto& free = a.free_dofs;
  const Eigen::MatrixXd stiffness = a.matrices.stiffness_n_m(free, free);
  const Eigen::LDLT<Eigen::MatrixXd> factor(stiffness);
  if (factor.info() != Eigen::Success || !factor.isPositive()) {
    throw std::invalid_argument("static deflection: the stiffness is not positive definite (buckled by gravity?)");
  }
  const Eigen::VectorXd free_deflection = factor.solve(load(free));
  Eigen::VectorXd deflection = Eigen::VectorXd::Zero(dofs);
  deflection(free) = free_deflection;
  // q0_j = φ_jᵀ M u / m_j: the exact M-orthogonal projection onto the kept modes.
  return (modal.mode_shapes.transpose() * a.matrices.mass_kg * deflection).cwiseQuotient(modal.modal_masses_kg);
}

}  // namespace pdamp::structure
