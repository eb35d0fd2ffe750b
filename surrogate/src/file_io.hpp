// Private file helpers of the surrogate module: atomic replacement and synced appends.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace pdamp::surrogate::detail {

/// The whole file as text; std::invalid_argument "<path>: cannot be read (reason)" if it cannot be opened.
std::string read_text_file(const std::filesystem::path& path);

/// Writes `contents` to a temporary file next to `path`, fsyncs it, renames it over
/// `path` and fsyncs the folder: readers see the old file or the new one, never a
/// partial one. std::runtime_error on any I/O failure (the temporary is removed).
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// Writes all of `data` to the open descriptor and fsyncs it; std::runtime_error on failure.
void write_all_synced(int fd, std::string_view data, const std::filesystem::path& path);

/// fsyncs the folder holding `path` so a newly created entry survives a crash (best effort).
void sync_parent_folder(const std::filesystem::path& path);

}  // namespace pdamp::surrogate::detail
