// Private file helpers of the surrogate module: safe reads of users' files, atomic
// replacement and synced appends.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "pdamp/base/output_file.hpp"

namespace pdamp::surrogate::detail {

/// The path as it appears in messages: base::printable(path), so a name holding a
/// newline or a control byte still gives a one-line message.
std::string file_label(const std::filesystem::path& path);

/// The whole file as bytes, through base::read_input_file: a directory, FIFO,
/// socket or device, a missing file or one above 256 MiB throws std::invalid_argument
/// "<path>: <reason>" at once (a FIFO never blocks the reader).
std::string read_text_file(const std::filesystem::path& path);

/// read_text_file + base::parse_json_document: std::invalid_argument
/// "<path>: malformed JSON: ..." or "<path>: <pointer>: duplicate key".
nlohmann::json read_json_file(const std::filesystem::path& path);

/// The atomic writer and synced appends of base (output_file.hpp).
using base::sync_parent_folder;
using base::write_all_synced;
using base::write_file_atomically;

}  // namespace pdamp::surrogate::detail
