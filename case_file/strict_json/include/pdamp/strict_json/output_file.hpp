// Writing result files so that no reader ever sees a partial one: a temporary file beside
// the target, written in full and fsynced, renamed over it, the folder fsynced. The one
// atomic writer of pdamp (field files, fits, checkpoints, DEM series, the output manifest).
#pragma once

#include <filesystem>
#include <string_view>

namespace pdamp::strict_json {

/// Writes `contents` to `path` atomically: readers see the old file or the new one, never a
/// partial one. The temporary `<path>.tmp.<pid>` sits in the same folder (rename() stays on
/// one file system; the pid keeps concurrent writers apart) and is removed on failure.
/// std::runtime_error naming the file on any I/O failure (a full disk, a missing folder).
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// Writes all of `data` to the open descriptor `fd` (retrying short writes and EINTR) and
/// fsyncs it; std::runtime_error naming `path` on failure.
void write_all_synced(int fd, std::string_view data, const std::filesystem::path& path);

/// fsyncs the folder holding `path`, so that a newly created or renamed entry survives a
/// crash (best effort: some file systems cannot open a folder).
void sync_parent_folder(const std::filesystem::path& path);

}  // namespace pdamp::strict_json
