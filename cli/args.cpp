// Strict parsing of subcommand flags.
#include "args.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "errors.hpp"

namespace pdamp::cli {

std::optional<double> parse_number(const std::string& text) {
  // Decimal notation only: strtod also takes hexadecimal ("0x10" = 16), "inf" and
  // "nan", which no user means as a clearance or a count.
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return std::nullopt;
  if (errno == ERANGE && std::abs(value) > 1.0) return std::nullopt;  // overflow (HUGE_VAL)
  return value;
}

std::string help_text(const CommandSpec& spec) {
  std::ostringstream out;
  out << "usage: " << spec.usage << "\n\n" << spec.summary << "\n";
  if (!spec.flags.empty()) out << "\noptions:\n";
  for (const auto& flag : spec.flags) {
    std::string head = "  " + flag.name + (flag.value_name.empty() ? "" : " " + flag.value_name);
    if (head.size() < 26) head.resize(26, ' ');
    else head += "\n" + std::string(26, ' ');
    out << head << flag.help << "\n";
  }
  out << "  --help                  show this help\n";
  return out.str();
}

ParsedArgs::ParsedArgs(const CommandSpec& spec, const std::vector<std::string>& args) : spec_(spec) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      help_ = true;
      continue;
    }
    if (arg.size() > 1 && arg[0] == '-' && !parse_number(arg)) {
      // "--flag=value" as well as "--flag value" (GNU style), "-o=DIR" too; the value is
      // everything after the first '=' (it may hold '=' itself).
      const std::size_t equals = arg.find('=');
      const std::string name = arg.substr(0, equals);
      const FlagSpec* flag = nullptr;
      for (const auto& f : spec.flags)
        if (f.name == name) flag = &f;
      if (flag == nullptr)
        throw InputError(name, "", "unknown option for 'pdamp " + spec.name + "' (see pdamp " + spec.name + " --help)");
      if (values_.count(name)) throw InputError(name, "", "given more than once");
      if (flag->value_name.empty()) {
        if (equals != std::string::npos) throw InputError(name, "", "takes no value");
        values_[name] = "";
      } else if (equals != std::string::npos) {
        values_[name] = arg.substr(equals + 1);
      } else {
        if (i + 1 >= args.size()) throw InputError(name, "", "needs a value (" + flag->value_name + ")");
        values_[name] = args[++i];
      }
      continue;
    }
    positional_.push_back(arg);
  }
  const auto wanted = static_cast<std::size_t>(spec.positional);
  if (!help_ && (positional_.size() < wanted || (positional_.size() > wanted && !spec.more_positional))) {
    if (positional_.size() > wanted)
      throw InputError(positional_[wanted], "", "unexpected argument (usage: " + spec.usage + ")");
    throw InputError("pdamp " + spec.name, "",
                     std::string(positional_.empty() ? "missing the case file" : "missing arguments") +
                         " (usage: " + spec.usage + ")");
  }
}

bool ParsedArgs::has(const std::string& flag) const { return values_.count(flag) > 0; }

std::optional<std::string> ParsedArgs::optional_text(const std::string& flag) const {
  const auto it = values_.find(flag);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::string ParsedArgs::text(const std::string& flag) const {
  auto value = optional_text(flag);
  if (!value) throw InputError(flag, "", "required (see pdamp " + spec_.name + " --help)");
  return *value;
}

std::optional<double> ParsedArgs::optional_number(const std::string& flag, const Range& range) const {
  const auto text_value = optional_text(flag);
  if (!text_value) return std::nullopt;
  const auto value = parse_number(*text_value);
  if (!value || !range.contains(*value)) throw InputError(flag, "", "'" + *text_value + "': " + range.text());
  return value;
}

double ParsedArgs::number(const std::string& flag, const Range& range) const {
  const auto value = optional_number(flag, range);
  if (!value) throw InputError(flag, "", "required, " + range.text());
  return *value;
}

std::optional<long long> ParsedArgs::optional_integer(const std::string& flag, long long min, long long max) const {
  const auto text_value = optional_text(flag);
  if (!text_value) return std::nullopt;
  const auto value = parse_number(*text_value);
  if (!value || *value != std::floor(*value) || *value < static_cast<double>(min) || *value > static_cast<double>(max))
    throw InputError(flag, "", "'" + *text_value + "': must be a whole number in [" + std::to_string(min) + ", " +
                                   std::to_string(max) + "]");
  return static_cast<long long>(*value);
}

std::vector<FlagSpec> concat_flags(std::vector<FlagSpec> first, const std::vector<FlagSpec>& rest) {
  first.insert(first.end(), rest.begin(), rest.end());
  return first;
}

}  // namespace pdamp::cli
