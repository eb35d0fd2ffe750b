// The error of a user's input file: which file, where in it (a JSON pointer), which rule.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace pdamp::base {

/// A rule an input file breaks. what() is "<file>: <pointer>: <rule>" ("<file>: <rule>"
/// when the pointer is empty, e.g. for a file that cannot be read), made printable on
/// one line (printable()): keys and strings quoted from a user's file may hold newlines
/// or NUL, which would break or cut a one-line message.
class InputError : public std::invalid_argument {
 public:
  InputError(std::string file, std::string pointer, std::string rule);
  const std::string& file() const { return file_; }
  /// RFC 6901 JSON pointer of the offending value ("/damper/particles/radius_m"), or "".
  const std::string& pointer() const { return pointer_; }
  const std::string& rule() const { return rule_; }

 private:
  std::string file_;
  std::string pointer_;
  std::string rule_;
};

/// JSON pointer reference token for `key` (RFC 6901: "~" -> "~0", "/" -> "~1").
std::string pointer_token(std::string_view key);

}  // namespace pdamp::base
