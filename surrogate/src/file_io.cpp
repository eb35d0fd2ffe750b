// Safe reads of users' files, shared by field and sweep files.
#include "file_io.hpp"


#include "pdamp/base/input_file.hpp"

namespace pdamp::surrogate::detail {

std::string file_label(const std::filesystem::path& path) { return base::printable(path.string()); }

std::string read_text_file(const std::filesystem::path& path) { return base::read_input_file(path.string()); }

nlohmann::json read_json_file(const std::filesystem::path& path) {
  return base::parse_json_document(read_text_file(path), path.string());
}

}  // namespace pdamp::surrogate::detail
