// Strict JSON import and export of modal data: every error names the JSON pointer and rule.
#include "pdamp/structure/imported_modal_data.hpp"
#include "pdamp/base/number_text.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"

namespace pdamp::structure {
namespace {

using nlohmann::json;

using base::format_number;

using base::pointer_token;

/// Checks the keys of one object: every key must be in `allowed`.
void reject_unknown_keys(const json& object, const std::string& at, const std::set<std::string>& allowed) {
  for (const auto& item : object.items()) {
    if (allowed.count(item.key()) == 0) {
      std::string names;
      for (const auto& name : allowed) names += (names.empty() ? "" : ", ") + name;
      throw ModalDataError(at + "/" + pointer_token(item.key()), "unknown key (allowed here: " + names + ")");
    }
  }
}

/// What a value must satisfy: a closed interval [min, max] (a physical range: wide enough for
/// any structure, narrow enough that a 1e-300 kg modal mass or a 1e308 Hz mode is refused
/// by name instead of overflowing a response).
struct Range {
  double min;
  double max;
};
constexpr Range kFrequency{1e-3, 1e5};     ///< Hz: a mHz mode to ultrasound
constexpr Range kDampingRatio{0.0, 1.0};   ///< ζ of a vibration mode
constexpr Range kModalMass{1e-6, 1e9};     ///< kg: a mg to a million tonnes
constexpr Range kShape{-1e6, 1e6};         ///< m or rad per unit q
constexpr Range kParticipation{-1e9, 1e9}; ///< kg per unit q
/// Modes and points a modal model may hold (as a beam's mode_count and named points).
constexpr std::size_t kMaxModes = 100;
constexpr std::size_t kMaxPoints = 1000;

double finite_number(const json& value, const std::string& at, Range range, std::string_view unit) {
  const std::string in_unit = unit.empty() ? "" : " (in " + std::string(unit) + ")";
  if (!value.is_number()) {
    throw ModalDataError(at, std::string("must be a finite number") + in_unit + ", got " + value.type_name());
  }
  const double x = value.get<double>();
  if (!std::isfinite(x)) throw ModalDataError(at, "must be a finite number" + in_unit);
  if (!(x >= range.min && x <= range.max))
    throw ModalDataError(at, format_number(x, 12) + " must be in [" + format_number(range.min, 12) + ", " +
                                 format_number(range.max, 12) + "]" + in_unit);
  return x;
}

/// An array of finite numbers, one per mode; `modes` empty for the frequencies themselves,
/// which set the mode count (at least one).
Eigen::VectorXd number_array(const json& value, const std::string& at, std::optional<Eigen::Index> modes, Range range,
                             std::string_view unit) {
  if (!value.is_array()) throw ModalDataError(at, std::string("must be a JSON array, got ") + value.type_name());
  const auto size = static_cast<Eigen::Index>(value.size());
  if (!modes && size == 0) throw ModalDataError(at, "must hold at least one mode, got an empty array");
  if (!modes && value.size() > kMaxModes)
    throw ModalDataError(at, "has " + std::to_string(size) + " modes: at most " + std::to_string(kMaxModes));
  if (modes && size != *modes) {
    throw ModalDataError(at, "has " + std::to_string(size) + " entries, must have " + std::to_string(*modes) +
                                 " (one per mode, as frequencies_hz)");
  }
  Eigen::VectorXd values(size);
  for (Eigen::Index j = 0; j < size; ++j) {
    values[j] = finite_number(value[static_cast<std::size_t>(j)], at + "/" + std::to_string(j), range, unit);
  }
  return values;
}

PointModeShape read_point(const std::string& name, const json& value, const std::string& at, Eigen::Index modes) {
  if (!value.is_object()) throw ModalDataError(at, std::string("must be a JSON object, got ") + value.type_name());
  reject_unknown_keys(value, at, {"translation_x", "translation_y", "rotation"});
  PointModeShape shape;
  shape.name = name;
  shape.translation = Eigen::MatrixXd::Zero(2, modes);
  shape.rotation = Eigen::RowVectorXd::Zero(modes);
  if (const auto it = value.find("translation_x"); it != value.end()) {
    shape.translation.row(0) = number_array(*it, at + "/translation_x", modes, kShape, "m per unit q").transpose();
  }
  if (const auto it = value.find("translation_y"); it != value.end()) {
    shape.translation.row(1) = number_array(*it, at + "/translation_y", modes, kShape, "m per unit q").transpose();
  }
  if (const auto it = value.find("rotation"); it != value.end()) {
    shape.rotation = number_array(*it, at + "/rotation", modes, kShape, "rad per unit q").transpose();
  }
  return shape;
}

}  // namespace

ModalDataError::ModalDataError(std::string pointer, const std::string& rule)
    : std::invalid_argument(base::printable((pointer.empty() ? "/" : pointer) + ": " + rule)),
      pointer_(std::move(pointer)) {}

ModalModel modal_model_from_json(const json& document) {
  if (!document.is_object()) {
    throw ModalDataError("", std::string("must be a JSON object, got ") + document.type_name());
  }
  reject_unknown_keys(document, "",
                      {"frequencies_hz", "damping_ratios", "modal_masses_kg", "points", "base_participation_x_kg",
                       "base_participation_y_kg"});
  const auto required = [&](const char* key) -> const json& {
    const auto it = document.find(key);
    if (it == document.end()) throw ModalDataError(std::string("/") + key, "missing (required key)");
    return *it;
  };

  ModalModel model;
  model.natural_frequencies_hz = number_array(required("frequencies_hz"), "/frequencies_hz", std::nullopt, kFrequency, "Hz");
  const Eigen::Index modes = model.natural_frequencies_hz.size();
  for (Eigen::Index j = 1; j < modes; ++j) {
    if (model.natural_frequencies_hz[j] < model.natural_frequencies_hz[j - 1]) {
      throw ModalDataError("/frequencies_hz/" + std::to_string(j),
                           format_number(model.natural_frequencies_hz[j], 12) + " must be >= the previous frequency " +
                               format_number(model.natural_frequencies_hz[j - 1], 12) + " Hz (ascending order)");
    }
  }

  const json& damping = required("damping_ratios");
  if (damping.is_array()) {
    model.damping_ratios = number_array(damping, "/damping_ratios", modes, kDampingRatio, "");
  } else {
    const double ratio = finite_number(damping, "/damping_ratios", kDampingRatio, "");
    model.damping_ratios = Eigen::VectorXd::Constant(modes, ratio);
  }

  if (const auto it = document.find("modal_masses_kg"); it != document.end()) {
    model.modal_masses_kg = number_array(*it, "/modal_masses_kg", modes, kModalMass, "kg");
  } else {
    model.modal_masses_kg = Eigen::VectorXd::Ones(modes);
  }

  const json& points = required("points");
  if (!points.is_object()) throw ModalDataError("/points", std::string("must be a JSON object, got ") + points.type_name());
  if (points.size() > kMaxPoints)
    throw ModalDataError("/points", "has " + std::to_string(points.size()) + " points: at most " + std::to_string(kMaxPoints));
  for (const auto& item : points.items()) {
    const std::string at = "/points/" + pointer_token(item.key());
    if (item.key().empty()) throw ModalDataError(at, "a point needs a non-empty name");
    model.points.push_back(read_point(item.key(), item.value(), at, modes));
  }

  const auto base_x = document.find("base_participation_x_kg");
  const auto base_y = document.find("base_participation_y_kg");
  if (base_x != document.end() || base_y != document.end()) {
    model.base_participation = Eigen::MatrixXd::Zero(modes, 2);
    if (base_x != document.end()) {
      model.base_participation.col(0) = number_array(*base_x, "/base_participation_x_kg", modes, kParticipation, "kg per unit q");
    }
    if (base_y != document.end()) {
      model.base_participation.col(1) = number_array(*base_y, "/base_participation_y_kg", modes, kParticipation, "kg per unit q");
    }
  }
  return model;
}

json modal_model_to_json(const ModalModel& model) {
  if (const auto problems = model.validate(); !problems.empty()) {
    std::string text;
    for (const auto& line : problems) text += (text.empty() ? "" : "; ") + line;
    throw std::invalid_argument(base::printable("modal model export: " + text));
  }
  const auto array = [](const auto& values) {
    json out = json::array();
    for (Eigen::Index j = 0; j < values.size(); ++j) out.push_back(values[j]);
    return out;
  };
  json document;
  document["frequencies_hz"] = array(model.natural_frequencies_hz);
  document["damping_ratios"] = array(model.damping_ratios);
  document["modal_masses_kg"] = array(model.modal_masses_kg);
  document["points"] = json::object();
  for (const auto& p : model.points) {
    document["points"][p.name] = {{"translation_x", array(p.translation.row(0))},
                                  {"translation_y", array(p.translation.row(1))},
                                  {"rotation", array(p.rotation)}};
  }
  if (model.base_participation.cols() == 2) {
    document["base_participation_x_kg"] = array(model.base_participation.col(0));
    document["base_participation_y_kg"] = array(model.base_participation.col(1));
  }
  return document;
}

}  // namespace pdamp::structure
