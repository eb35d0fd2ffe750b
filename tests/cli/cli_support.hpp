// Helpers of the command-line tests: shipped and edited case files, the error contract.
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>

#include "support/run_pdamp.hpp"

namespace pdamp::test {

inline std::string case_path(const std::string& name) { return std::string(PDAMP_SOURCE_DIR) + "/cases/" + name; }

/// Whether gnuplot is there to draw the pictures (without it the scripts are written alone).
inline bool gnuplot_installed() {
  for (const char* dir : {"/usr/bin", "/usr/local/bin", "/bin"})
    if (::access((std::filesystem::path(dir) / "gnuplot").c_str(), X_OK) == 0) return true;
  return false;
}

/// pdamp's --json output of a command that must succeed (exit 0, one JSON object on stdout).
inline nlohmann::json run_json(std::vector<std::string> args) {
  args.push_back("--json");
  const auto r = run_pdamp(args);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return nlohmann::json::parse(r.out);
}

/// The shipped case `name` with one edit applied, written into `dir` as case.json.
inline std::string edited_shipped_case(const std::filesystem::path& dir, const std::string& name,
                                       const std::function<void(nlohmann::json&)>& edit) {
  std::ifstream in(case_path(name));
  nlohmann::json c = nlohmann::json::parse(in);
  edit(c);
  const std::filesystem::path path = dir / "case.json";
  std::ofstream(path) << c.dump(2);
  return path.string();
}

/// Writes a case built from the shipped low-intensity case with one edit applied.
inline std::string edited_case(const std::string& name, const std::function<void(nlohmann::json&)>& edit) {
  std::ifstream in(case_path("low_intensity_36_spheres.json"));
  nlohmann::json c = nlohmann::json::parse(in);
  edit(c);
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << c.dump(2);
  return path.string();
}

/// docs/command_line.md: exit 2, nothing on stdout, one line `pdamp: error: ...` on stderr.
inline void require_one_line_error(const RunResult& r, const std::string& must_contain) {
  CHECK(r.exit_code == 2);
  CHECK(r.out.empty());
  CHECK(r.err.rfind("pdamp: error: ", 0) == 0);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_THAT(r.err, Catch::Contains(must_contain));
}

/// Every .csv in `dir` reads as one table with pandas' and R's defaults: the first line
/// is the header (no `#` line before it), every other non-blank line has its number of
/// fields (blank lines only separate gnuplot's blocks and are skipped by those readers).
inline void require_plain_csv_tables(const std::filesystem::path& dir) {
  std::size_t tables = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".csv") continue;
    ++tables;
    INFO(entry.path().string());
    std::ifstream in(entry.path());
    std::string line;
    REQUIRE(std::getline(in, line));
    CHECK(line.rfind('#', 0) == std::string::npos);
    const auto fields = std::count(line.begin(), line.end(), ',');
    std::size_t row = 1;
    while (std::getline(in, line)) {
      ++row;
      if (line.empty()) continue;
      INFO("line " << row << ": " << line);
      CHECK(std::count(line.begin(), line.end(), ',') == fields);
      if (std::count(line.begin(), line.end(), ',') != fields) break;  // one message per file
    }
  }
  CHECK(tables > 0);
}

}  // namespace pdamp::test
