// Atomic result files, gnuplot plots and readable tables.
#include "output.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace pdamp::cli {

namespace fs = std::filesystem;

void write_file_atomically(const fs::path& path, const std::string& content) {
  const fs::path tmp = path.string() + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
    out << content;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

OutputDir::OutputDir(fs::path dir) : dir_(std::move(dir)) {
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error || !fs::is_directory(dir_))
    throw std::runtime_error("cannot create output directory " + dir_.string());
  staging_ = dir_ / (".pdamp-staging-" + std::to_string(::getpid()));
  fs::remove_all(staging_, error);
  fs::create_directory(staging_);
}

OutputDir::~OutputDir() {
  std::error_code error;
  fs::remove_all(staging_, error);
}

fs::path OutputDir::add(const std::string& name, const std::string& content) {
  std::ofstream out(staging_ / name, std::ios::binary | std::ios::trunc);
  out << content;
  if (!out) throw std::runtime_error("cannot write " + (staging_ / name).string());
  names_.push_back(name);
  return dir_ / name;
}

fs::path OutputDir::staged_path(const std::string& name) {
  names_.push_back(name);
  return staging_ / name;
}

fs::path OutputDir::add_json(const std::string& name, const nlohmann::json& value) {
  return add(name, value.dump(2) + "\n");
}

bool gnuplot_available() {
  static const bool available = std::system("command -v gnuplot >/dev/null 2>&1") == 0;
  return available;
}

std::vector<std::string> OutputDir::add_plot(const std::string& script_name, const std::string& script,
                                             const std::vector<std::string>& outputs) {
  add(script_name, script);
  if (!gnuplot_available())
    return {"gnuplot not found: wrote " + script_name + " and its data; run 'gnuplot " + script_name +
            "' in the output directory for the plots"};
  const std::string command = "cd '" + staging_.string() + "' && gnuplot '" + script_name + "' 2>gnuplot.log";
  const int status = std::system(command.c_str());
  std::vector<std::string> warnings;
  if (status != 0) warnings.push_back("gnuplot failed on " + script_name + " (see its log); data files are written");
  for (const auto& name : outputs) {
    if (fs::exists(staging_ / name)) names_.push_back(name);
    else if (status == 0) warnings.push_back("gnuplot did not produce " + name);
  }
  return warnings;
}

std::vector<std::string> OutputDir::commit() {
  std::vector<std::string> paths;
  for (const auto& name : names_) {
    fs::rename(staging_ / name, dir_ / name);
    paths.push_back((dir_ / name).string());
  }
  return paths;
}

std::string key_value_table(const std::vector<std::pair<std::string, std::string>>& rows) {
  std::size_t width = 0;
  for (const auto& row : rows) width = std::max(width, row.first.size());
  std::ostringstream out;
  for (const auto& [key, value] : rows) out << key << std::string(width + 2 - key.size(), ' ') << value << "\n";
  return out.str();
}

std::string format_number(double value, int significant) {
  if (std::isnan(value)) return "n/a";
  std::ostringstream out;
  out.precision(significant);
  out << value;
  return out.str();
}

}  // namespace pdamp::cli
