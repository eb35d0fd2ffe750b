// Validation of modal data.
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

std::vector<std::string> ModalModel::validate() const {
  std::vector<std::string> errors;
  const auto modes = natural_frequencies_hz.size();
  if (damping_ratios.size() != modes || mode_shapes.cols() != modes)
    errors.push_back("modal model: frequencies, damping ratios and mode shapes must have one entry per mode");
  for (Eigen::Index j = 0; j < natural_frequencies_hz.size(); ++j)
    if (!(natural_frequencies_hz[j] > 0.0)) errors.push_back("modal model: natural frequency must be > 0 Hz");
  for (Eigen::Index j = 0; j < damping_ratios.size(); ++j)
    if (!(damping_ratios[j] >= 0.0)) errors.push_back("modal model: damping ratio must be >= 0");
  return errors;
}

}  // namespace pdamp::structure
