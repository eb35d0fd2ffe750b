// ModalModel: look-up of named points and validation of the modal data (sizes, ranges).
#include "pdamp/structure/modal_model.hpp"
#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "pdamp/base/input_file.hpp"

namespace pdamp::structure {
namespace {

using base::format_number;

/// "<field> has N <what>, must have M (one per mode)" if the sizes differ.
void check_count(std::vector<std::string>& problems, const std::string& field, Eigen::Index count,
                 Eigen::Index modes, const std::string& what) {
  if (count != modes) {
    problems.push_back(field + " has " + std::to_string(count) + " " + what + ", must have " +
                       std::to_string(modes) + " (one per mode)");
  }
}

/// The first non-finite entry of `values` as "<field>/<row>/<col> = <value>: must be finite".
void check_finite(std::vector<std::string>& problems, const std::string& field, const Eigen::MatrixXd& values) {
  for (Eigen::Index col = 0; col < values.cols(); ++col) {
    for (Eigen::Index row = 0; row < values.rows(); ++row) {
      if (!std::isfinite(values(row, col))) {
        problems.push_back(field + "/" + std::to_string(row) + "/" + std::to_string(col) + " = " +
                           format_number(values(row, col), 12) + ": must be finite");
        return;  // one line per field: a NaN matrix would otherwise flood the report
      }
    }
  }
}

}  // namespace

const PointModeShape& ModalModel::point(const std::string& name) const {
  for (const auto& p : points) {
    if (p.name == name) return p;
  }
  std::string known;
  for (const auto& p : points) known += (known.empty() ? "" : ", ") + p.name;
  throw std::invalid_argument(base::printable("modal model: no point named \"" + name + "\" (known: " +
                                                  (known.empty() ? "none" : known) + ")"));
}

std::vector<std::string> ModalModel::validate() const {
  std::vector<std::string> problems;
  const Eigen::Index modes = natural_frequencies_hz.size();
  if (modes == 0) problems.emplace_back("natural_frequencies_hz is empty: a modal model needs at least one mode");

  for (Eigen::Index j = 0; j < modes; ++j) {
    const double f = natural_frequencies_hz[j];
    const std::string field = "natural_frequencies_hz/" + std::to_string(j) + " = " + format_number(f, 12);
    if (!(f > 0.0) || !std::isfinite(f)) {
      problems.push_back(field + ": must be > 0 Hz and finite");
    } else if (j > 0 && f < natural_frequencies_hz[j - 1]) {
      problems.push_back(field + ": must be >= the previous frequency (ascending order)");
    }
  }

  check_count(problems, "damping_ratios", damping_ratios.size(), modes, "entries");
  for (Eigen::Index j = 0; j < damping_ratios.size(); ++j) {
    if (!(damping_ratios[j] >= 0.0) || !std::isfinite(damping_ratios[j])) {
      problems.push_back("damping_ratios/" + std::to_string(j) + " = " + format_number(damping_ratios[j], 12) +
                         ": must be >= 0 and finite");
    }
  }

  check_count(problems, "modal_masses_kg", modal_masses_kg.size(), modes, "entries");
  for (Eigen::Index j = 0; j < modal_masses_kg.size(); ++j) {
    if (!(modal_masses_kg[j] > 0.0) || !std::isfinite(modal_masses_kg[j])) {
      problems.push_back("modal_masses_kg/" + std::to_string(j) + " = " + format_number(modal_masses_kg[j], 12) +
                         ": must be > 0 kg and finite");
    }
  }

  std::set<std::string> names;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const PointModeShape& p = points[i];
    const std::string field = "points/" + std::to_string(i);
    if (p.name.empty()) problems.push_back(field + "/name is empty: every point needs a name");
    if (!names.insert(p.name).second) {
      problems.push_back(base::printable(field + "/name = \"" + p.name + "\": must be unique"));
    }
    if (p.translation.rows() != 2) {
      problems.push_back(field + "/translation has " + std::to_string(p.translation.rows()) +
                         " rows, must have 2 (x, y)");
    }
    check_count(problems, field + "/translation", p.translation.cols(), modes, "columns");
    check_count(problems, field + "/rotation", p.rotation.size(), modes, "entries");
    check_finite(problems, field + "/translation", p.translation);
    check_finite(problems, field + "/rotation", p.rotation);
  }

  if (base_participation.size() != 0 || base_participation.cols() != 0) {
    if (base_participation.cols() != 2) {
      problems.push_back("base_participation has " + std::to_string(base_participation.cols()) +
                         " columns, must have 2 (x, y) or 0 (no base motion)");
    }
    check_count(problems, "base_participation", base_participation.rows(), modes, "rows");
    check_finite(problems, "base_participation", base_participation);
  }

  if (mode_shapes.size() != 0) {
    check_count(problems, "mode_shapes", mode_shapes.cols(), modes, "columns");
    check_finite(problems, "mode_shapes", mode_shapes);
  }
  return problems;
}

Eigen::VectorXd modal_static_deflection_amplitudes(const ModalModel& model, const std::string& point,
                                                   const Eigen::Vector2d& force_n) {
  const PointModeShape& p = model.point(point);
  using detail::kTwoPi;
  Eigen::VectorXd q(model.mode_count());
  for (Eigen::Index j = 0; j < model.mode_count(); ++j) {
    const double omega = kTwoPi * model.natural_frequencies_hz[j];
    q[j] = p.translation.col(j).dot(force_n) / (model.modal_masses_kg[j] * omega * omega);
  }
  return q;
}

}  // namespace pdamp::structure
