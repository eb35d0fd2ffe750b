// Records (base/record.hpp): one field list gives a result's JSON, the exact codec and the
// CSV columns, and they cannot disagree on a name.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"

using namespace pdamp;
using nlohmann::json;

namespace {

enum class Side { kLeft, kRight };
std::string_view to_string(Side side) { return side == Side::kLeft ? "left" : "right"; }

struct Inner {
  double value = 0.0;
  static const base::Fields<Inner>& fields() {
    static const auto f = base::Fields<Inner>().field("value_m", &Inner::value, "m", "a length");
    return f;
  }
};

struct Sample {
  std::string name;
  Side side = Side::kLeft;
  double spread = NAN;
  std::vector<double> amplitude;  // one per output
  std::vector<double> phase;      // one per output
  std::int64_t steps = 0;
  bool converged = false;
  double window_change = NAN;
  std::vector<double> series;
  std::optional<Inner> inner;
  int analysed = 0, transient = 0;

  static const base::Fields<Sample>& fields() {
    using S = Sample;
    static const auto f =
        base::Fields<S>()
            .field("name", &S::name, "", "a label")
            .field("side", &S::side, "", "left or right")
            .field("spread", &S::spread, "1", "may be unknown", base::kNullable)
            .field("amplitude", &S::amplitude, "m", "per output", base::kPerOutput)
            .field("phase_deg", &S::phase, "deg", "per output", base::kPerOutput)
            .field("steps", &S::steps, "", "a count")
            .field("converged", &S::converged, "", "a flag")
            .group("window", "a nested object",
                   base::Fields<S>().field("change", &S::window_change, "1", "may be unknown", base::kNullable))
            .field("series", &S::series, "m", "state only the codec carries", base::kHidden)
            .field("inner", &S::inner, "", "present or not", base::kOmitEmpty)
            .field("analysed", &S::analysed, "", "periods analysed")
            .field("transient", &S::transient, "", "periods before")
            .derived("periods", [](const S& s) { return s.analysed + s.transient; }, "", "periods run");
    return f;
  }
};

Sample sample() {
  Sample s;
  s.name = "a\nb";  // any text
  s.side = Side::kRight;
  s.amplitude = {1.0 / 3.0, -0.0};
  s.phase = {90.0, -1e-300};
  s.steps = std::int64_t{1} << 53;
  s.converged = true;
  s.series = {0.1, NAN, std::numeric_limits<double>::infinity()};
  s.analysed = 8;
  s.transient = 3;
  return s;
}

bool same_bits(double a, double b) { return (std::isnan(a) && std::isnan(b)) || (a == b && std::signbit(a) == std::signbit(b)); }

}  // namespace

TEST_CASE("a record's result JSON names every entry once, unknown numbers as null", "[record]") {
  const std::vector<std::string> outputs = {"wide", "narrow"};
  const json j = base::to_json(sample(), &outputs);
  CHECK(j["name"] == "a\nb");
  CHECK(j["side"] == "right");  // an enum by its name
  CHECK(j["spread"].is_null());
  CHECK(j["amplitude"]["wide"] == 1.0 / 3.0);
  CHECK(j["phase_deg"]["narrow"] == -1e-300);
  CHECK(j["steps"] == std::int64_t{1} << 53);
  CHECK(j["converged"] == true);
  CHECK(j["window"]["change"].is_null());
  CHECK(j["periods"] == 11);
  CHECK_FALSE(j.contains("series"));  // codec only
  CHECK_FALSE(j.contains("inner"));   // empty and left out
  CHECK(j.size() == 11);
  // Without output names, per-output values are arrays.
  CHECK(base::to_json(sample())["amplitude"].is_array());
  Sample with_inner = sample();
  with_inner.inner = Inner{2.5};
  CHECK(base::to_json(with_inner)["inner"]["value_m"] == 2.5);
}

// The codec is what crosses a process boundary (base::to_job_bytes): every member comes
// back bit for bit, NaN, infinity and -0 included; a derived entry is not carried.
TEST_CASE("a record survives its codec bit for bit", "[record]") {
  Sample s = sample();
  s.inner = Inner{std::nextafter(1.0, 2.0)};
  const Sample back = base::from_job_bytes<Sample>(base::to_job_bytes(s));
  CHECK(back.name == s.name);
  CHECK(back.side == s.side);
  CHECK(same_bits(back.spread, s.spread));
  REQUIRE(back.amplitude.size() == 2);
  CHECK(same_bits(back.amplitude[1], -0.0));
  CHECK(same_bits(back.phase[1], -1e-300));
  CHECK(back.steps == s.steps);
  CHECK(back.converged);
  CHECK(same_bits(back.window_change, s.window_change));
  REQUIRE(back.series.size() == 3);
  CHECK(std::isnan(back.series[1]));
  CHECK(back.series[2] == std::numeric_limits<double>::infinity());
  REQUIRE(back.inner);
  CHECK(back.inner->value == std::nextafter(1.0, 2.0));
  CHECK(back.analysed == 8);
  CHECK_FALSE(json(s).contains("periods"));
}

TEST_CASE("a view writes the named entries under their own or new keys", "[record]") {
  const auto view = Sample::fields().view({"name", "first=window/change", "periods"});
  const json j = view.to_json(sample());
  CHECK(j.size() == 3);
  CHECK(j["first"].is_null());
  CHECK(j["periods"] == 11);
  CHECK_THROWS_AS(Sample::fields().view({"no_such_entry"}), std::logic_error);
}

TEST_CASE("a CSV table's header and rows come from the same columns", "[record]") {
  const base::CsvTable<Sample> table(
      {"name", "side", {"amplitude", "phase_deg"}, base::CsvColumn("spread").nan_as("0").named_for_first_output(),
       "converged", "steps", base::CsvColumn("window/change").nan_as(""), "periods"},
      {"w", "n"});
  Sample s = sample();
  s.name = "x";
  CHECK(table.header("case") ==
        "case,name,side,amplitude_w,phase_deg_w,amplitude_n,phase_deg_n,spread_w,converged,steps,window_change,periods");
  CHECK(table.row(s, "c") == "c,x,right,0.3333333333,90,-0,-1e-300,0,1,9007199254740992,,11");
  CHECK(table.row(s).starts_with("x,"));
  // The first output only.
  const base::CsvTable<Sample> first({base::CsvColumn("amplitude").first_output_only()}, {"w", "n"});
  CHECK(first.header() == "amplitude_w");
  CHECK(first.row(s) == "0.3333333333");
  // A column that is not an entry is refused when the table is made, not when it is written.
  CHECK_THROWS_AS(base::CsvTable<Sample>({"no_such_column"}), std::logic_error);
}

TEST_CASE("describe lists every entry with its unit and meaning", "[record]") {
  const json d = Sample::fields().describe();
  REQUIRE(d.size() == Sample::fields().entries().size());
  CHECK(d[3]["name"] == "amplitude");
  CHECK(d[3]["unit"] == "m");
  CHECK(d[7]["fields"][0]["name"] == "change");
}
