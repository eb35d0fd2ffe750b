// Private file helpers of the surrogate module: safe reads of users' files, atomic
// replacement and synced appends.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace pdamp::surrogate::detail {

/// The path as it appears in messages: formulas::printable(path), so a name holding a
/// newline or a control byte still gives a one-line message.
std::string file_label(const std::filesystem::path& path);

/// The whole file as bytes, through formulas::read_input_file: a directory, FIFO,
/// socket or device, a missing file or one above 256 MiB throws std::invalid_argument
/// "<path>: <reason>" at once (a FIFO never blocks the reader).
std::string read_text_file(const std::filesystem::path& path);

/// read_text_file + formulas::parse_json_document: std::invalid_argument
/// "<path>: malformed JSON: ..." or "<path>: <pointer>: duplicate key".
nlohmann::json read_json_file(const std::filesystem::path& path);

/// Writes `contents` to a temporary file next to `path`, fsyncs it, renames it over
/// `path` and fsyncs the folder: readers see the old file or the new one, never a
/// partial one. std::runtime_error on any I/O failure (the temporary is removed).
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// Writes all of `data` to the open descriptor and fsyncs it; std::runtime_error on failure.
void write_all_synced(int fd, std::string_view data, const std::filesystem::path& path);

/// fsyncs the folder holding `path` so a newly created entry survives a crash (best effort).
void sync_parent_folder(const std::filesystem::path& path);

}  // namespace pdamp::surrogate::detail
