// Command-line flags of one subcommand: declared with unit and default, parsed
// strictly (unknown flag, missing value, non-finite number: InputError).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "limits.hpp"

namespace pdamp::cli {

struct FlagSpec {
  std::string name;         ///< "--clearance" or "-o"
  std::string value_name;   ///< "M", "HZ", "DIR"; empty for a switch
  std::string help;         ///< meaning, unit and default
};

struct CommandSpec {
  std::string name;         ///< "loss"
  std::string usage;        ///< "pdamp loss --model M --clearance M ..."
  std::string summary;      ///< one paragraph
  std::vector<FlagSpec> flags;
  int positional = 0;       ///< number of positional arguments (a case file)
  bool more_positional = false;  ///< `positional` is the least number, more may follow (shard files)
};

std::string help_text(const CommandSpec& spec);

/// `first` followed by `rest` (a command's own flags and a shared group).
std::vector<FlagSpec> concat_flags(std::vector<FlagSpec> first, const std::vector<FlagSpec>& rest);

class ParsedArgs {
 public:
  ParsedArgs(const CommandSpec& spec, const std::vector<std::string>& args);
  bool has(const std::string& flag) const;
  bool help_requested() const { return help_; }
  std::string text(const std::string& flag) const;  ///< InputError when missing
  std::optional<std::string> optional_text(const std::string& flag) const;
  /// A finite number; InputError naming the flag and the allowed range when missing,
  /// malformed or outside [min, max] (min_exclusive: > min).
  double number(const std::string& flag, const Range& range) const;
  std::optional<double> optional_number(const std::string& flag, const Range& range) const;
  /// A whole number in [min, max] ("1.5" is refused, not rounded).
  std::optional<long long> optional_integer(const std::string& flag, long long min, long long max) const;
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  const CommandSpec& spec_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
  bool help_ = false;
};

/// Strict number parsing: the whole text must be a finite decimal number (a value that
/// underflows to a subnormal or to zero is returned as it is, for the range check to
/// judge; one that overflows is not a number).
std::optional<double> parse_number(const std::string& text);

}  // namespace pdamp::cli
