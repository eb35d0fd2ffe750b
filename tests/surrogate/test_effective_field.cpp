// Tests of the effective-field file format: round trip, strict rejection of bad files, atomic writes.
#include <unistd.h>

#include <catch2/catch.hpp>

#include "support/temp_dir.hpp"
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "pdamp/surrogate/effective_field.hpp"
#include "surrogate/hostile_files.hpp"

namespace {

using namespace pdamp::surrogate;
using nlohmann::json;
namespace fs = std::filesystem;

using pdamp::test::TempDir;

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

/// A 3 x 4 field with every kind of cell: a log axis, unknown stderr, a missing point, labels.
EffectiveField sample_field() {
  EffectiveField field;
  field.grid = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 3.0, 3, AxisSpacing::kLinear},
                                 {0.001, 0.1, 4, AxisSpacing::kLog});
  field.clearance_m = 0.04;
  field.bed_mass_kg = 0.74;
  field.provenance = {FieldSource::kDem, "0123456789abcdef", 3, "0.1.0", "2024-05-06T07:08:09Z"};
  for (std::size_t k = 0; k < field.grid.size(); ++k) {
    FieldPoint p;
    p.eta_star = 0.1 + 0.01 * static_cast<double>(k) + 1.0 / 3.0;  // not short in decimal
    p.eta_star_stderr = k % 2 == 0 ? 0.01 : FieldPoint::kUnknown;
    p.e_diss_j = 1e-3 * static_cast<double>(k + 1);
    p.apparent_mass_kg = 0.2 + 1e-17;
    p.apparent_mass_fraction = 0.2 / 0.74;
    p.motion_mode = k < 6 ? "rolling" : "collect_and_collide";
    p.status = PointStatus::kOk;
    field.points.push_back(p);
  }
  field.points[5] = FieldPoint{};  // missing: every value unknown
  field.points[7].status = PointStatus::kFailed;
  field.points[7].eta_star = field.points[7].e_diss_j = FieldPoint::kUnknown;
  field.points[7].motion_mode = "unstable time step";
  return field;
}

/// Expects reading `doc` as `file` to fail with a message naming the file, the pointer and the rule.
void check_rejected(const json& doc, const std::string& pointer, const std::string& rule) {
  INFO("pointer " << pointer);
  CHECK_THROWS_AS(effective_field_from_json(doc, "bad.json"), std::invalid_argument);
  CHECK_THROWS_WITH(effective_field_from_json(doc, "bad.json"),
                    Catch::StartsWith("bad.json: " + pointer + ": ") && Catch::Contains(rule));
}

}  // namespace

TEST_CASE("a field written and read back is identical", "[surrogate]") {
  TempDir dir("field_round_trip");
  const EffectiveField field = sample_field();
  const fs::path path = dir.path / "field.json";
  write_effective_field(field, path);
  const EffectiveField back = read_effective_field(path);
  CHECK(back == field);  // bit-exact doubles: nlohmann writes shortest round-trip text
  CHECK(effective_field_from_json(to_json(field), "memory") == field);

  // Self-describing: units of every column and the axes are in the file.
  const json doc = json::parse(std::ifstream(path));
  CHECK(doc["format"] == "pdamp.effective_field");
  CHECK(doc["columns"][4] == json({{"name", "e_diss_j"}, {"unit", "J"}}));
  CHECK(doc["axes"][1]["spacing"] == "log");
  CHECK(doc["table"][5][2].is_null());
  CHECK(doc["table"][7][8] == "failed");
  CHECK_FALSE(doc["provenance"].contains("approach_amplitude_m"));  // from rest: as written before the key existed

  // The descending branch's approach stroke is kept.
  EffectiveField descending = field;
  descending.provenance.approach_amplitude_m = 0.025;
  CHECK(to_json(descending)["provenance"]["approach_amplitude_m"] == 0.025);
  CHECK(effective_field_from_json(to_json(descending), "memory") == descending);

  // Overwriting is atomic and leaves no temporary behind.
  write_effective_field(field, path);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path)) ++files;
  CHECK(files == 1);
}

TEST_CASE("the reader rejects bad files naming file, JSON pointer and rule", "[surrogate]") {
  const json good = to_json(sample_field());
  auto changed = [&](const std::function<void(json&)>& change) {
    json doc = good;
    change(doc);
    return doc;
  };
  SECTION("wrong units") {
    check_rejected(changed([](json& d) { d["axes"][1]["unit"] = "mm"; }), "/axes/1/unit", "is \"mm\", must be \"m\"");
    check_rejected(changed([](json& d) { d["columns"][4]["unit"] = "kJ"; }), "/columns/4/unit", "must be \"J\"");
    check_rejected(changed([](json& d) { d["columns"][2].erase("unit"); }), "/columns/2/unit", "missing");
  }
  SECTION("missing or wrong axes") {
    check_rejected(changed([](json& d) { d.erase("axes"); }), "/axes", "missing (required key)");
    check_rejected(changed([](json& d) { d["axes"].erase(1); }), "/axes", "has 1 entries, must have 2");
    check_rejected(changed([](json& d) { d["axes"][0]["name"] = "stroke_over_clearance"; }), "/axes/0/name",
                   "cannot be axis 0");
    check_rejected(changed([](json& d) {
                     d["axes"][0]["name"] = "intensity";
                     d["axes"][0]["unit"] = "1";
                   }),
                   "/axes", "must be (frequency_hz, amplitude_m) or (intensity, stroke_over_clearance)");
    check_rejected(changed([](json& d) { d["axes"][0]["values"] = json::array(); }), "/axes/0/values",
                   "at least one node");
    check_rejected(changed([](json& d) { d["axes"][1]["spacing"] = "cubic"; }), "/axes/1/spacing",
                   "must be \"linear\" or \"log\"");
  }
  SECTION("non-monotone axes") {
    check_rejected(changed([](json& d) { d["axes"][0]["values"][2] = 1.5; }), "/axes/0/values/2",
                   "strictly increasing");
    check_rejected(changed([](json& d) { d["axes"][1]["values"][0] = -0.001; }), "/axes/1/values/0", "must be > 0");
  }
  SECTION("NaN, infinity and null") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    check_rejected(changed([&](json& d) { d["clearance_m"] = nan; }), "/clearance_m", "must be a finite number (in m)");
    check_rejected(changed([&](json& d) { d["table"][3][4] = std::numeric_limits<double>::infinity(); }), "/table/3/4",
                   "must be a finite number (in J)");
    check_rejected(changed([](json& d) { d["table"][3][2] = nullptr; }), "/table/3/2",
                   "null: must be a finite number for status \"ok\"");
    check_rejected(changed([](json& d) { d["table"][5][2] = 0.3; }), "/table/5/2",
                   "must be null for status \"missing\"");
    check_rejected(changed([](json& d) { d["axes"][0]["values"][1] = nullptr; }), "/axes/0/values/1",
                   "must be a finite number (in Hz), got null");
    check_rejected(changed([](json& d) { d["table"][0][3] = -0.1; }), "/table/0/3", "must be >= 0 or null");
  }
  SECTION("unknown keys") {
    check_rejected(changed([](json& d) { d["colour"] = "red"; }), "/colour", "unknown key (allowed here:");
    check_rejected(changed([](json& d) { d["provenance"]["operator"] = "me"; }), "/provenance/operator", "unknown key");
    check_rejected(changed([](json& d) {
                     d["columns"].push_back({{"name", "phase_rad"}, {"unit", "rad"}});
                   }),
                   "/columns/9/name", "unknown column \"phase_rad\"");
  }
  SECTION("shape mismatch") {
    check_rejected(changed([](json& d) { d["table"].erase(11); }), "/table", "has 11 rows, the axes need 3 x 4 = 12");
    check_rejected(changed([](json& d) { d["table"][2].erase(8); }), "/table/2", "must be an array of 9 entries");
    check_rejected(changed([](json& d) { std::swap(d["table"][0], d["table"][1]); }), "/table/0/1",
                   "does not match the axis node");
    check_rejected(changed([](json& d) { d["columns"].erase(3); }), "/columns", "missing column \"eta_star_stderr\"");
    check_rejected(changed([](json& d) { d["columns"][3] = d["columns"][2]; }), "/columns/3/name", "appears twice");
  }
  SECTION("format, version, provenance and labels") {
    check_rejected(changed([](json& d) { d["format"] = "csv"; }), "/format", "must be \"pdamp.effective_field\"");
    check_rejected(changed([](json& d) { d["format_version"] = 2; }), "/format_version", "must be in [1, 1]");
    check_rejected(changed([](json& d) { d["provenance"]["source"] = "guess"; }), "/provenance/source",
                   "must be \"formulas\", \"dem\" or \"measured\"");
    check_rejected(changed([](json& d) { d["provenance"]["created_utc"] = "yesterday"; }), "/provenance/created_utc",
                   "UTC ISO 8601");
    check_rejected(changed([](json& d) { d["provenance"]["approach_amplitude_m"] = -0.01; }),
                   "/provenance/approach_amplitude_m", "");
    check_rejected(changed([](json& d) { d["provenance"]["model_version"] = 1.5; }), "/provenance/model_version",
                   "must be an integer");
    check_rejected(changed([](json& d) { d["table"][0][8] = "done"; }), "/table/0/8",
                   "must be \"ok\", \"missing\" or \"failed\"");
    check_rejected(changed([](json& d) { d["table"][0][7] = 3; }), "/table/0/7", "must be a string");
    check_rejected(changed([](json& d) { d["storage_order"] = "column_major"; }), "/storage_order",
                   "must be \"row_major\"");
    check_rejected(json::array(), "/", "must be a JSON object");
  }
  SECTION("columns may come in any order") {
    json doc = good;
    std::swap(doc["columns"][2], doc["columns"][6]);
    for (auto& row : doc["table"]) std::swap(row[2], row[6]);
    CHECK(effective_field_from_json(doc, "reordered.json") == sample_field());
  }
}

TEST_CASE("files that are not JSON or not there are rejected naming the file", "[surrogate]") {
  TempDir dir("field_bad_files");
  const std::string text = to_json(sample_field()).dump();
  const fs::path nan_file = dir.path / "nan.json";
  std::string with_nan = text;
  with_nan.replace(with_nan.find("0.04"), 4, "NaN");  // clearance_m: JSON has no NaN
  write_text(nan_file, with_nan);
  CHECK_THROWS_WITH(read_effective_field(nan_file), Catch::StartsWith(nan_file.string() + ": malformed JSON: "));
  const fs::path inf_file = dir.path / "inf.json";
  std::string with_inf = text;
  with_inf.replace(with_inf.find("0.04"), 4, "1e999");
  write_text(inf_file, with_inf);
  CHECK_THROWS_WITH(read_effective_field(inf_file), Catch::Contains("number overflow"));
  CHECK_THROWS_WITH(read_effective_field(dir.path / "absent.json"), Catch::EndsWith("absent.json: no such file"));
}

TEST_CASE("a field file with a repeated key is refused naming the key's pointer", "[surrogate]") {
  // nlohmann::json keeps the last of two equal keys: an edit of the first would be ignored.
  TempDir dir("field_duplicate_key");
  std::string text = to_json(sample_field()).dump();
  text.replace(text.find("\"clearance_m\":0.04"), 18, "\"clearance_m\":0.04,\"clearance_m\":0.05");
  const fs::path path = dir.path / "dup.json";
  write_text(path, text);
  CHECK_THROWS_WITH(read_effective_field(path), Catch::Equals(path.string() +
                                                             ": /clearance_m: duplicate key (each key may appear "
                                                             "once in an object)"));
}

TEST_CASE("a directory or a FIFO given as a field file is refused at once, naming it", "[surrogate]") {
  TempDir dir("field_hostile");
  CHECK_THROWS_WITH(read_effective_field(dir.path), Catch::Equals(dir.path.string() + ": is a directory, not a file"));
  const fs::path fifo = dir.path / "field.json";
  pdamp::test::make_fifo(fifo);
  // The old reader (std::ifstream) blocked in open() forever; the guard turns that into a failure.
  CHECK(pdamp::test::invalid_argument_within_timeout([&] { read_effective_field(fifo); }, fifo) ==
        fifo.string() + ": is a FIFO (named pipe), not a file");
}

TEST_CASE("a motion mode with control characters and a grid above the node limit are refused", "[surrogate]") {
  const json good = to_json(sample_field());
  json doc = good;
  doc["table"][0][7] = std::string("roll\0ing\n", 9);
  check_rejected(doc, "/table/0/7", "\"roll\\0ing\\n\" holds control characters");
  doc = good;
  // 1001 x 1000 nodes: one more row of nodes than kMaxGridNodes allows.
  json& f = doc["axes"][0]["values"];
  json& x = doc["axes"][1]["values"];
  f = json::array();
  x = json::array();
  for (int k = 1; k <= 1001; ++k) f.push_back(k);
  for (int k = 1; k <= 1000; ++k) x.push_back(1e-4 * k);
  check_rejected(doc, "/axes", "1001 x 1000 = 1001000 nodes, must be <= 1000000");
}

TEST_CASE("invalid fields are not written", "[surrogate]") {
  TempDir dir("field_invalid_write");
  EffectiveField field = sample_field();
  field.points.pop_back();
  CHECK_THROWS_WITH(write_effective_field(field, dir.path / "f.json"),
                    Catch::Contains("11 points for a grid of 3 x 4"));
  field = sample_field();
  field.points[0].eta_star = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(to_json(field), Catch::Contains("points[0].eta_star = inf: must be finite for status ok"));
  CHECK_FALSE(fs::exists(dir.path / "f.json"));
}

TEST_CASE("case hashes depend on content, not on key order or layout", "[surrogate]") {
  const json a = json::parse(R"({"damper": {"clearance_m": 0.04, "count": 36}, "name": "x"})");
  const json b = json::parse(R"({ "name":"x", "damper":{"count":36,"clearance_m":0.04} })");
  const json c = json::parse(R"({"damper": {"clearance_m": 0.05, "count": 36}, "name": "x"})");
  CHECK(case_hash(a) == case_hash(b));
  CHECK(case_hash(a) != case_hash(c));
  CHECK(case_hash(a).size() == 16);
  CHECK(case_hash(a).find_first_not_of("0123456789abcdef") == std::string::npos);
}

TEST_CASE("provenance is stamped with this build and the current UTC time", "[surrogate]") {
  const Provenance p = make_provenance(FieldSource::kMeasured, "abc", 2);
  CHECK(p.pdamp_version == std::string(pdamp_version()));
  CHECK(p.created_utc.size() == 20);
  CHECK(p.created_utc.back() == 'Z');
  CHECK(field_source_from_string("dem") == FieldSource::kDem);
  CHECK_FALSE(point_status_from_string("OK").has_value());
}
