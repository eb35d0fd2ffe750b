// Reading a user's input file (case, field, CSV, fit) safely: only a regular file is
// opened, so a FIFO, a device or a directory is refused at once instead of hanging or
// failing deep inside a parser (docs/bad_inputs.md).
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "pdamp/base/input_error.hpp"

namespace pdamp::base {

/// Largest input file read (256 MiB): far above any case, field or measured CSV, and
/// small enough that a mistaken path (a disk image, /dev/zero) cannot exhaust memory.
inline constexpr std::size_t kMaxInputFileBytes = std::size_t{256} << 20;

/// The whole file as bytes. InputError "<path>: <reason>" when the path
/// does not exist, is not a regular file (directory, FIFO, socket, device), cannot be
/// read or is larger than max_bytes (kMaxInputFileBytes; a checkpoint allows more). The file is opened without blocking, so
/// a FIFO swapped in after the check cannot hang the caller either.
std::string read_input_file(const std::string& path, std::size_t max_bytes = kMaxInputFileBytes);

/// Deepest nesting of arrays and objects a pdamp file may have (the deepest, a case file,
/// needs about 8).
inline constexpr std::size_t kMaxNestingDepth = 64;

/// Parses `text` (read from `path`) as one JSON document, refusing what
/// nlohmann::json would accept silently: a key repeated in one object (the parser keeps
/// the last one, so an edit that seems to change a value may not), and nesting deeper than
/// kMaxNestingDepth (refused where it is met, before the rest is parsed). InputError
/// "<path>: malformed JSON: <where and what>" or "<path>: <pointer>: duplicate key".
nlohmann::json parse_json_document(const std::string& text, const std::string& path);

/// Whether `text` is valid UTF-8 (what a JSON document may hold: paths written into results
/// must be).
bool valid_utf8(const std::string& text);

/// `text` made printable on one line: control bytes (newline, NUL, ESC, ...) and bytes
/// of invalid UTF-8 become \n, \0, \x1b ... escapes, so a message quoting a user's
/// input stays one line and is not cut at a NUL byte.
std::string printable(const std::string& text);

/// `name` as a safe single file-name component: letters, digits, '.', '-', '_' and
/// '+' are kept, every other byte (a '/', "..", a NUL, a quote, a space) becomes '_', a
/// leading '.' or '-' is replaced and the length is capped at 100 bytes, so a name cannot
/// steer a path out of its folder nor exceed a file system's name length.
std::string safe_file_name(const std::string& name);

}  // namespace pdamp::base
