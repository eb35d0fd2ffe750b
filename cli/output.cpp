// Readable tables of the subcommands (output.hpp).
#include "output.hpp"

#include <sstream>

namespace pdamp::cli {

std::string key_value_table(const std::vector<std::pair<std::string, std::string>>& rows) {
  std::size_t width = 0;
  for (const auto& row : rows) width = std::max(width, row.first.size());
  std::ostringstream out;
  for (const auto& [key, value] : rows) out << key << std::string(width + 2 - key.size(), ' ') << value << "\n";
  return out.str();
}

}  // namespace pdamp::cli
