// Writing result files so that no reader ever sees a partial one: a temporary file beside
// the target, written in full and fsynced, renamed over it, the folder fsynced. The one
// atomic writer of pdamp (field files, fits, checkpoints, DEM series, the output manifest).
#pragma once

#include <filesystem>
#include <string_view>

namespace pdamp::base {

/// Writes `contents` to `path` atomically: readers see the old file or the new one, never a
/// partial one. The temporary `<path>.tmp.<pid>` sits in the same folder (rename() stays on
/// one file system; the pid keeps concurrent writers apart) and is removed on failure.
/// std::runtime_error naming the file on any I/O failure (a full disk, a missing folder).
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// Creates (or empties) `path` and writes `contents` to it in full, fsynced and closed: a
/// staged result file. On failure the file is removed and std::runtime_error names
/// `shown_as` (the path the user will look for; `path` when empty) and the reason.
void write_file_synced(const std::filesystem::path& path, std::string_view contents,
                       const std::filesystem::path& shown_as = {});

/// fsyncs the regular file `path` written by another writer (gnuplot, a library), so that
/// its data is on disk (a delayed write error shows here) before it replaces an earlier
/// result; std::runtime_error naming `shown_as` when it is missing, not a regular file or
/// cannot be synced.
void sync_file(const std::filesystem::path& path, const std::filesystem::path& shown_as);

/// Writes all of `data` to the open descriptor `fd` (retrying short writes and EINTR) and
/// fsyncs it; std::runtime_error naming `path` on failure.
void write_all_synced(int fd, std::string_view data, const std::filesystem::path& path);

/// fsyncs the folder holding `path`, so that a newly created or renamed entry survives a
/// crash (best effort: some file systems cannot open a folder).
void sync_parent_folder(const std::filesystem::path& path);

/// True when `pid_digits` (the decimal suffix of a temporary's name) names no running
/// process: the temporary is garbage left by a killed writer.
bool names_a_dead_process(std::string_view pid_digits);

}  // namespace pdamp::base
