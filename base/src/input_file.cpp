// Safe reading of users' input files and their errors (input_file.hpp, input_error.hpp).
#include "pdamp/base/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <set>
#include <string_view>
#include <utility>
#include <stdexcept>
#include <vector>

namespace pdamp::base {

namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& reason) {
  throw InputError(path, "", reason);
}

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return "not a regular file";
}

/// Length of the valid UTF-8 sequence starting at s[i] (0 when invalid).
std::size_t utf8_length(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char lead = byte(i);
  std::size_t n = lead >= 0xF0 && lead <= 0xF4 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC2 && lead < 0xE0 ? 2 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  return n;
}

}  // namespace

InputError::InputError(std::string file, std::string pointer, std::string rule)
    : std::invalid_argument(printable(file + (pointer.empty() ? "" : ": " + pointer) + ": " + rule)),
      file_(std::move(file)),
      pointer_(std::move(pointer)),
      rule_(std::move(rule)) {}

std::string pointer_token(std::string_view key) {
  std::string token;
  for (char c : key) token += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
  return token;
}

bool valid_utf8(const std::string& text) {
  for (std::size_t i = 0; i < text.size();) {
    if (static_cast<unsigned char>(text[i]) < 0x80) {
      ++i;
      continue;
    }
    const std::size_t n = utf8_length(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
    } else if (c == '\n') {
      out += "\\n";
      ++i;
    } else if (c == '\t') {
      out += "\\t";
      ++i;
    } else if (c == '\r') {
      out += "\\r";
      ++i;
    } else if (c == 0) {
      out += "\\0";
      ++i;
    } else if (const std::size_t n = c >= 0x80 ? utf8_length(text, i) : 0; n > 0) {
      out.append(text, i, n);  // printable non-ASCII text (names in other scripts) stays
      i += n;
    } else {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\x%02x", c);
      out += escape;
      ++i;
    }
  }
  return out;
}

std::string read_input_file(const std::string& path, std::size_t max_bytes) {
  if (path.empty()) refuse("''", "empty file name");
  // O_NONBLOCK: opening a FIFO for reading with no writer would block forever.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int error = errno;
    struct stat info {};
    if (error == ENOENT) refuse(path, "no such file");
    if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode)) refuse(path, std::string("is ") + kind_of(info.st_mode) + ", not a file");
    refuse(path, std::string("cannot be opened (") + std::strerror(error) + ")");
  }
  struct FileCloser {
    int fd;
    ~FileCloser() { ::close(fd); }
  } closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0) refuse(path, std::string("cannot be read (") + std::strerror(errno) + ")");
  if (!S_ISREG(info.st_mode)) refuse(path, std::string("is ") + kind_of(info.st_mode) + ", not a file");
  if (static_cast<unsigned long long>(info.st_size) > max_bytes)
    refuse(path, "is " + std::to_string(info.st_size >> 20) + " MiB, larger than the " +
                     std::to_string(max_bytes >> 20) + " MiB an input file may have");
  std::string bytes;
  bytes.resize(static_cast<std::size_t>(info.st_size));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) refuse(path, std::string("read failed (") + std::strerror(errno) + ")");
    if (n == 0) break;  // the file shrank while being read: take what is there
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

namespace {

/// The parser's position: one frame per open object or array, for duplicate-key
/// detection and for naming where a duplicate sits.
struct Frame {
  bool object = true;
  std::set<std::string> keys;
  std::string key;        // the object's current key
  std::size_t index = 0;  // the array's current element
};

std::string pointer_of(const std::vector<Frame>& frames) {
  std::string pointer;
  // The last frame is the object holding the duplicate; its parents give the path.
  for (std::size_t i = 0; i + 1 < frames.size(); ++i)
    pointer += "/" + (frames[i].object ? pointer_token(frames[i].key) : std::to_string(frames[i].index));
  return pointer;
}

struct DuplicateKey {
  std::string pointer;
};
struct TooDeep {
  std::string pointer;
};

/// nlohmann::json's own DOM builder with the strict reader's checks on the way: a key twice
/// in one object, nesting deeper than kMaxNestingDepth (refused as it is met: a file of 20 MB
/// of "[" parsed whole took a minute and 2 GB). A SAX handler, not the library's parser
/// callback: the callback parser rescans the enclosing container at every object's end
/// (nlohmann 3.11's json_sax_dom_callback_parser::end_object), O(n²) for an array of n
/// objects (200,000 supports took 9 s, 400,000 a minute). The builder's methods are called
/// statically by sax_parse, so shadowing them is enough.
class StrictDomBuilder : public nlohmann::detail::json_sax_dom_parser<nlohmann::json> {
  using Base = nlohmann::detail::json_sax_dom_parser<nlohmann::json>;

 public:
  explicit StrictDomBuilder(nlohmann::json& result) : Base(result, true) {}

  bool start_object(std::size_t elements) {
    enter(true);
    return Base::start_object(elements);
  }
  bool start_array(std::size_t elements) {
    enter(false);
    return Base::start_array(elements);
  }
  bool key(std::string& name) {
    Frame& top = frames_.back();
    top.key = name;
    if (!top.keys.insert(name).second) throw DuplicateKey{pointer_of(frames_) + "/" + pointer_token(name)};
    return Base::key(name);
  }
  bool end_object() {
    leave();
    return Base::end_object();
  }
  bool end_array() {
    leave();
    return Base::end_array();
  }
  bool null() { return element_done(), Base::null(); }
  bool boolean(bool value) { return element_done(), Base::boolean(value); }
  bool number_integer(nlohmann::json::number_integer_t value) { return element_done(), Base::number_integer(value); }
  bool number_unsigned(nlohmann::json::number_unsigned_t value) { return element_done(), Base::number_unsigned(value); }
  bool number_float(nlohmann::json::number_float_t value, const std::string& text) {
    return element_done(), Base::number_float(value, text);
  }
  bool string(std::string& value) { return element_done(), Base::string(value); }
  bool binary(nlohmann::json::binary_t& value) { return element_done(), Base::binary(value); }

 private:
  void enter(bool object) {
    if (frames_.size() >= kMaxNestingDepth) throw TooDeep{pointer_of(frames_)};
    frames_.push_back({object, {}, {}, 0});
  }
  void leave() {
    frames_.pop_back();
    element_done();
  }
  void element_done() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  std::vector<Frame> frames_;
};

}  // namespace

nlohmann::json parse_json_document(const std::string& text, const std::string& path) {
  using nlohmann::json;
  // The parser stops at a NUL byte as at the end of the text, so "{...}\0garbage" would
  // pass: a NUL has no place in JSON text (RFC 8259: control characters only escaped).
  if (const auto nul = text.find('\0'); nul != std::string::npos)
    throw InputError(path, "", "malformed JSON: a NUL byte at offset " + std::to_string(nul) +
                                   " (a binary file, or text with a NUL)");
  try {
    json result;
    StrictDomBuilder builder(result);
    json::sax_parse(text, &builder);  // a parse error throws (the builder allows exceptions)
    return result;
  } catch (const DuplicateKey& duplicate) {
    throw InputError(path, duplicate.pointer, "duplicate key (each key may appear once in an object)");
  } catch (const TooDeep& deep) {
    throw InputError(path, deep.pointer,
                     "malformed JSON: arrays and objects nested deeper than " + std::to_string(kMaxNestingDepth) +
                         " levels (no pdamp file needs more than 10)");
  } catch (const json::exception& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line 1, column 9: ..."
    // or "[json.exception.out_of_range.406] number overflow parsing '1e400'".
    std::string what = e.what();
    const auto start = what.find("] ");
    throw InputError(path, "", "malformed JSON: " + (start == std::string::npos ? what : what.substr(start + 2)));
  }
}

std::string safe_file_name(const std::string& name) {
  std::string out;
  for (char c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                      c == '-' || c == '_' || c == '+';
    out += keep ? c : '_';
  }
  if (out.size() > 100) out.resize(100);
  if (out.empty()) out = "case";
  if (out[0] == '.' || out[0] == '-') out[0] = '_';
  return out;
}

}  // namespace pdamp::base
