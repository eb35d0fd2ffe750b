// Checkpoints of long runs (docs/dem.md "Checkpoints"): the binary encoding
// of a run's state and the file that carries it.
//
// A state is a flat little-endian byte string written by StateWriter and read back by
// StateReader, which trusts nothing: every count is bounded by the bytes left, every
// value is checked by its caller (finite, in range, consistent with the options), and
// any mismatch is std::invalid_argument naming the field. A checkpoint file is
//   "PDAMP-CHECKPOINT 1\n" + one line of JSON (the header) + "\n" + the payload,
// where the header carries the run's kind, the case's physics hash, the DEM's physics
// model version and the payload's length and FNV-1a 64 hash, so that a checkpoint of
// another case, model version or kind, and a damaged or truncated file, are refused.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pdamp::dem_reference {

/// Appends fields to a byte string (little-endian, IEEE doubles bit for bit).
class StateWriter {
 public:
  void u8(std::uint8_t value);
  void i32(std::int32_t value);
  void i64(std::int64_t value);
  void f64(double value);
  void text(std::string_view value);  ///< length, then the bytes
  void f64s(const std::vector<double>& values);  ///< count, then the values
  void i32s(const std::vector<int>& values);
  /// A section marker: a reader that lost its place fails at the next one, naming it.
  void tag(std::string_view name);
  const std::string& bytes() const { return bytes_; }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

/// Reads what a StateWriter wrote, in the same order. Every method throws
/// std::invalid_argument "<what>: <field>: ..." when the bytes end early or a count
/// exceeds what the bytes can hold.
class StateReader {
 public:
  StateReader(std::string_view bytes, std::string what);
  std::uint8_t u8(const char* field);
  bool boolean(const char* field);  ///< a u8 that must be 0 or 1
  std::int32_t i32(const char* field);
  /// An i32 in [min, max].
  std::int32_t i32_in(const char* field, std::int32_t min, std::int32_t max);
  std::int64_t i64(const char* field);
  double f64(const char* field);
  double finite(const char* field);  ///< an f64 that must be finite
  std::string text(const char* field, std::size_t max_length);
  /// `count` doubles written by f64s (the stored count must equal it); each finite.
  std::vector<double> finite_f64s(const char* field, std::size_t count);
  /// Doubles written by f64s with any count up to `max_count`; each finite.
  std::vector<double> finite_f64s_up_to(const char* field, std::size_t max_count);
  /// `count` ints written by i32s, each in [min, max].
  std::vector<int> i32s(const char* field, std::size_t count, int min, int max);
  void expect_tag(std::string_view name);
  /// A count (i64) of entries of at least `min_entry_bytes` bytes each, in [0, max]:
  /// refused when the bytes left cannot hold them (a hostile count cannot allocate).
  std::size_t count(const char* field, std::size_t max, std::size_t min_entry_bytes);
  std::size_t remaining() const { return bytes_.size() - at_; }
  /// Refuses bytes left over (a state of another layout).
  void finish() const;
  [[noreturn]] void fail(const std::string& field, const std::string& rule) const;

 private:
  const unsigned char* take(std::size_t n, const char* field);
  std::string_view bytes_;
  std::size_t at_ = 0;
  std::string what_;
};

/// What a checkpoint says about itself (the JSON header line).
struct CheckpointHeader {
  std::string kind;          ///< the run it continues ("decay_dem", ...): a resume of another kind is refused
  std::string case_hash;     ///< the case's physics hash (case_file::physics_hash) at the checkpoint
  int physics_model_version = 0;  ///< kPhysicsModelVersion at the checkpoint
  /// What the run was asked (flags, durations) as text: a resume with other settings is refused.
  std::string settings;
  double simulated_time_s = 0.0;  ///< progress at the checkpoint, s (for messages)
  double end_time_s = 0.0;        ///< the run's planned end, s
};

/// The file's bytes: magic line, header, payload.
std::string encode_checkpoint(const CheckpointHeader& header, std::string_view payload);

struct DecodedCheckpoint {
  CheckpointHeader header;
  std::string payload;
};
/// Parses a checkpoint file's bytes (read from `file`). base::InputError naming the
/// file, the header key and the rule: a missing magic line, malformed or incomplete header
/// JSON, unknown keys, a payload of another length or hash (damaged or truncated).
DecodedCheckpoint decode_checkpoint(std::string_view bytes, const std::string& file);

/// Largest checkpoint file read, bytes (4 GiB: a bed of about ten million spheres).
inline constexpr std::size_t kMaxCheckpointBytes = std::size_t{4} << 30;

}  // namespace pdamp::dem_reference
