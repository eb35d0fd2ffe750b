// Splitting of simple CSV lines (no quoting), shared by pdamp's CSV readers.
#pragma once

#include <string_view>
#include <vector>

namespace pdamp::base {

/// `text` without leading and trailing blanks (space, tab, CR, LF).
inline std::string_view trim_blanks(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

/// The comma-separated cells of one line, each trimmed; views into `line`.
inline std::vector<std::string_view> split_csv_line(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t begin = 0;
  while (true) {
    const auto comma = line.find(',', begin);
    cells.push_back(trim_blanks(line.substr(begin, comma == std::string_view::npos ? line.npos : comma - begin)));
    if (comma == std::string_view::npos) return cells;
    begin = comma + 1;
  }
}

}  // namespace pdamp::base
