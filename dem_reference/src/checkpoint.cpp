// Binary state encoding and checkpoint files (checkpoint.hpp).
#include "pdamp/dem_reference/checkpoint.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "pdamp/base/fnv1a.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/strict_object.hpp"

namespace pdamp::dem_reference {

namespace {

constexpr std::string_view kMagic = "PDAMP-CHECKPOINT 1\n";
/// Longest header line: a few hundred bytes of JSON; a file without a newline soon after
/// the magic is no checkpoint.
constexpr std::size_t kMaxHeaderBytes = 1 << 16;

void put_u64(std::string& out, std::uint64_t value) {
  for (int b = 0; b < 8; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xFFu));
}

std::uint64_t get_u64(const unsigned char* p) {
  std::uint64_t value = 0;
  for (int b = 7; b >= 0; --b) value = (value << 8) | p[b];
  return value;
}

std::string hex(std::uint64_t value) {
  std::ostringstream out;
  out << std::hex;
  out.width(16);
  out.fill('0');
  out << value;
  return out.str();
}

}  // namespace

void StateWriter::u8(std::uint8_t value) { bytes_.push_back(static_cast<char>(value)); }
void StateWriter::i32(std::int32_t value) {
  const auto u = static_cast<std::uint32_t>(value);
  for (int b = 0; b < 4; ++b) bytes_.push_back(static_cast<char>((u >> (8 * b)) & 0xFFu));
}
void StateWriter::i64(std::int64_t value) { put_u64(bytes_, static_cast<std::uint64_t>(value)); }
void StateWriter::f64(double value) { put_u64(bytes_, std::bit_cast<std::uint64_t>(value)); }
void StateWriter::text(std::string_view value) {
  i64(static_cast<std::int64_t>(value.size()));
  bytes_.append(value);
}
void StateWriter::f64s(const std::vector<double>& values) {
  i64(static_cast<std::int64_t>(values.size()));
  for (double v : values) f64(v);
}
void StateWriter::i32s(const std::vector<int>& values) {
  i64(static_cast<std::int64_t>(values.size()));
  for (int v : values) i32(v);
}
void StateWriter::tag(std::string_view name) { text(name); }

StateReader::StateReader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

void StateReader::fail(const std::string& field, const std::string& rule) const {
  throw std::invalid_argument(what_ + ": " + field + ": " + rule);
}

const unsigned char* StateReader::take(std::size_t n, const char* field) {
  if (n > remaining())
    fail(field, "the state ends early (" + std::to_string(remaining()) + " bytes left, " + std::to_string(n) +
                    " needed): damaged or of another layout");
  const auto* p = reinterpret_cast<const unsigned char*>(bytes_.data() + at_);
  at_ += n;
  return p;
}

std::uint8_t StateReader::u8(const char* field) { return *take(1, field); }

bool StateReader::boolean(const char* field) {
  const std::uint8_t v = u8(field);
  if (v > 1) fail(field, "= " + std::to_string(v) + ": must be 0 or 1");
  return v == 1;
}

std::int32_t StateReader::i32(const char* field) {
  const unsigned char* p = take(4, field);
  std::uint32_t u = 0;
  for (int b = 3; b >= 0; --b) u = (u << 8) | p[b];
  return static_cast<std::int32_t>(u);
}

std::int32_t StateReader::i32_in(const char* field, std::int32_t min, std::int32_t max) {
  const std::int32_t v = i32(field);
  if (v < min || v > max)
    fail(field, "= " + std::to_string(v) + ": must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  return v;
}

std::int64_t StateReader::i64(const char* field) { return static_cast<std::int64_t>(get_u64(take(8, field))); }

double StateReader::f64(const char* field) { return std::bit_cast<double>(get_u64(take(8, field))); }

double StateReader::finite(const char* field) {
  const double v = f64(field);
  if (!std::isfinite(v)) fail(field, "is not finite");
  return v;
}

std::size_t StateReader::count(const char* field, std::size_t max, std::size_t min_entry_bytes) {
  const std::int64_t c = i64(field);
  if (c < 0 || static_cast<std::uint64_t>(c) > max)
    fail(field, "count " + std::to_string(c) + ": must be in [0, " + std::to_string(max) + "]");
  const auto n = static_cast<std::size_t>(c);
  if (min_entry_bytes > 0 && n > remaining() / min_entry_bytes)
    fail(field, "count " + std::to_string(n) + " exceeds what the " + std::to_string(remaining()) +
                    " bytes left can hold: damaged or of another layout");
  return n;
}

std::string StateReader::text(const char* field, std::size_t max_length) {
  const std::size_t n = count(field, max_length, 1);
  const unsigned char* p = take(n, field);
  return {reinterpret_cast<const char*>(p), n};
}

std::vector<double> StateReader::finite_f64s(const char* field, std::size_t expected) {
  const std::size_t n = count(field, expected, 8);
  if (n != expected) fail(field, "holds " + std::to_string(n) + " values: must hold " + std::to_string(expected));
  std::vector<double> values(n);
  for (auto& v : values) v = finite(field);
  return values;
}

std::vector<double> StateReader::finite_f64s_up_to(const char* field, std::size_t max_count) {
  const std::size_t n = count(field, max_count, 8);
  std::vector<double> values(n);
  for (auto& v : values) v = finite(field);
  return values;
}

std::vector<int> StateReader::i32s(const char* field, std::size_t expected, int min, int max) {
  const std::size_t n = count(field, expected, 4);
  if (n != expected) fail(field, "holds " + std::to_string(n) + " values: must hold " + std::to_string(expected));
  std::vector<int> values(n);
  for (auto& v : values) v = i32_in(field, min, max);
  return values;
}

void StateReader::expect_tag(std::string_view name) {
  const std::string field = "section " + std::string(name);
  const std::string found = text(field.c_str(), 64);
  if (found != name) fail(field, "found '" + base::printable(found) + "': damaged or of another layout");
}

void StateReader::finish() const {
  if (remaining() != 0)
    fail("end", std::to_string(remaining()) + " bytes are left over: a state of another layout");
}

std::string encode_checkpoint(const CheckpointHeader& header, std::string_view payload) {
  const nlohmann::json h = {{"kind", header.kind},
                            {"case_hash", header.case_hash},
                            {"physics_model_version", header.physics_model_version},
                            {"settings", header.settings},
                            {"simulated_time_s", header.simulated_time_s},
                            {"end_time_s", header.end_time_s},
                            {"payload_bytes", payload.size()},
                            {"payload_fnv1a64", hex(base::fnv1a64(payload))}};
  std::string out(kMagic);
  out += h.dump();  // one line: dump() without indent has no newline
  out += '\n';
  out.append(payload);
  return out;
}

DecodedCheckpoint decode_checkpoint(std::string_view bytes, const std::string& file) {
  if (bytes.substr(0, kMagic.size()) != kMagic)
    throw base::InputError(file, "", "not a pdamp checkpoint (it must start with 'PDAMP-CHECKPOINT 1')");
  const std::size_t start = kMagic.size();
  const std::size_t end = bytes.find('\n', start);
  if (end == std::string_view::npos || end - start > kMaxHeaderBytes)
    throw base::InputError(file, "", "the checkpoint's header line is missing or longer than 64 KiB");
  const nlohmann::json json = base::parse_json_document(std::string(bytes.substr(start, end - start)), file);
  base::StrictObject h(json, "", file);
  DecodedCheckpoint out;
  out.header.kind = h.string("kind");
  out.header.case_hash = h.string("case_hash");
  out.header.physics_model_version = static_cast<int>(h.integer("physics_model_version", 1, 1000000));
  out.header.settings = h.string("settings");
  out.header.simulated_time_s = h.number("simulated_time_s", false, "s");
  out.header.end_time_s = h.number("end_time_s", false, "s");
  const auto size = static_cast<std::size_t>(h.integer("payload_bytes", 0, static_cast<long long>(kMaxCheckpointBytes)));
  const std::string hash = h.string("payload_fnv1a64");
  h.finish();
  const std::string_view payload = bytes.substr(end + 1);
  if (payload.size() != size)
    base::fail_at(file, "/payload_bytes",
                         "= " + std::to_string(size) + " but the file holds " + std::to_string(payload.size()) +
                             " payload bytes: the checkpoint is truncated or damaged");
  if (hex(base::fnv1a64(payload)) != hash)
    base::fail_at(file, "/payload_fnv1a64", "does not match the payload: the checkpoint is damaged");
  out.payload = std::string(payload);
  return out;
}

}  // namespace pdamp::dem_reference
