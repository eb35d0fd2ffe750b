// Modal data imported from JSON (a user's own FE package, a measured modal survey, a
// 1-DOF oscillator as one mode) and the inverse export. Format: docs/structures.md,
// "Imported modal data".
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <stdexcept>
#include <string>

#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// An invalid modal-data document: what() is "<pointer>: <rule>" on one line (the rule
/// states the allowed range); pointer() is the RFC 6901 JSON pointer of the offending
/// key or value ("" for the document itself, printed as "/" in what()).
class ModalDataError : public std::invalid_argument {
 public:
  ModalDataError(std::string pointer, const std::string& rule);
  const std::string& pointer() const { return pointer_; }

 private:
  std::string pointer_;
};

/// Reads a modal model from a JSON object with the keys
///   frequencies_hz           array of f_j, Hz, > 0, ascending (one entry per mode; >= 1 mode)
///   damping_ratios           array of ζ_j >= 0, or one number for every mode
///   modal_masses_kg          optional array of m_j > 0 kg (default 1: mass-normalised shapes)
///   points                   object: name -> {"translation_x": [...], "translation_y": [...],
///                            "rotation": [...]}, one value per mode (m or rad per unit q),
///                            a missing component is 0
///   base_participation_x_kg  optional array Γ_jx (kg per unit q); if only one of x, y is
///   base_participation_y_kg  given the other is 0; with neither, the model takes no base motion
/// Strict: unknown keys, wrong types or lengths, non-finite or out-of-range values throw
/// ModalDataError. The result has no full mode_shapes.
ModalModel modal_model_from_json(const nlohmann::json& document);

/// The inverse of modal_model_from_json (full mode_shapes are not exported). Throws
/// std::invalid_argument if the model does not validate.
nlohmann::json modal_model_to_json(const ModalModel& model);

}  // namespace pdamp::structure
