// `field`: the effective-field grid of the (first) damper layer.
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "readers.hpp"

namespace pdamp::case_file::detail {

namespace {

void read_axis_range(ObjectReader& r, surrogate::AxisRange& range, const surrogate::AxisRange& defaults,
                     const Range& axis_limits, const std::string& unit) {
  range.min = r.number("min", defaults.min, axis_limits, unit);
  range.max = r.number("max", defaults.max, axis_limits, unit);
  range.count = r.integer("count", defaults.count, 1, 10000);
  range.spacing = r.text("spacing", std::string(defaults.spacing == surrogate::AxisSpacing::kLog ? "log" : "linear"),
                         {"linear", "log"}) == "log"
                      ? surrogate::AxisSpacing::kLog
                      : surrogate::AxisSpacing::kLinear;
  if (range.max < range.min || (range.max == range.min && range.count != 1))
    r.fail("max", "must be > min (or equal to min with count 1)");
}

}  // namespace

/// Default grid: the case frequency and strokes from 0.1 h to 1.0 h (10 points), or
/// Γ at that frequency and X/h over the same range.
void read_field(ObjectReader& r, Case& c) {
  FieldSpec& field = c.field;
  const std::string axes =
      r.text("axes", std::string("frequency_amplitude"), {"frequency_amplitude", "intensity_stroke_over_clearance"});
  const double h = c.dampers.front().layers.front().clearance_m;
  const double f = c.excitation.frequency_hz;
  surrogate::AxisRange default0{f, f, 1, surrogate::AxisSpacing::kLinear};
  // Strokes from 0.1 h to 1.0 h, within the range of a stroke (a 50 m clearance would
  // ask for 50 m strokes, a key the case never wrote).
  surrogate::AxisRange default1{std::min(0.1 * h, 0.5 * limits::kStroke.max), std::min(1.0 * h, limits::kStroke.max), 10,
                                surrogate::AxisSpacing::kLinear};
  std::string unit0 = " Hz", unit1 = " m";
  if (axes == "intensity_stroke_over_clearance") {
    field.axes = surrogate::GridAxes::kIntensityStrokeOverClearance;
    default0 = {0.5, 0.5, 1, surrogate::AxisSpacing::kLinear};
    default1 = {0.1, 1.0, 10, surrogate::AxisSpacing::kLinear};
    unit0 = unit1 = "";
  }
  const Range limits0 = field.axes == surrogate::GridAxes::kFrequencyAmplitude ? limits::kFrequency : limits::kIntensity;
  const Range limits1 = field.axes == surrogate::GridAxes::kFrequencyAmplitude ? limits::kStroke : Range{0.0, 100.0, true};
  const auto read0 = [&](ObjectReader& a) { read_axis_range(a, field.axis0, default0, limits0, unit0); };
  const auto read1 = [&](ObjectReader& a) { read_axis_range(a, field.axis1, default1, limits1, unit1); };
  r.object("axis0", false, read0);
  if (!r.has("axis0")) {
    ObjectReader fallback(r.file(), empty_object(), r.pointer() + "/axis0", r.resolved()["axis0"]);
    read0(fallback);
  }
  r.object("axis1", false, read1);
  if (!r.has("axis1")) {
    ObjectReader fallback(r.file(), empty_object(), r.pointer() + "/axis1", r.resolved()["axis1"]);
    read1(fallback);
  }
  field.threads = r.integer("threads", 2, 1, 256);
  surrogate::Grid grid;
  try {
    grid = surrogate::Grid::from_ranges(field.axes, field.axis0, field.axis1);  // the node limit, spacing rules
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  // The sweep's own rules (nodes strictly increasing: min and max a rounding apart with
  // count 3 give equal nodes), as pdamp field checks them.
  if (const auto problems = grid.validate(); !problems.empty()) r.fail("", problems.front());
  // Every node must be a drive pdamp can evaluate: on intensity axes Γ and X/h give
  // f = √(Γg/X)/2π, which leaves the frequency range for tiny X/h.
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const auto drive = surrogate::drive_point(grid, k, h);
    for (const auto& [name, value, range] :
         {std::tuple{"frequency_hz", drive.frequency_hz, limits::kFrequency}, std::tuple{"amplitude_m", drive.amplitude_m, limits::kStroke}}) {
      if (range.contains(value)) continue;
      std::ostringstream out;
      out.precision(10);
      out << "node " << k << " (axis0 = " << grid.coordinate0(k) << ", axis1 = " << grid.coordinate1(k) << ") drives at "
          << name << " = " << value << ": " << range.text() << " (narrow the axes)";
      r.fail("", out.str());
    }
  }
}

}  // namespace pdamp::case_file::detail
