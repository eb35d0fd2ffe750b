// A bed's field along a free decay (decay_field.hpp).
#include "pdamp/surrogate/decay_field.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "pdamp/formulas/collect_and_collide.hpp"

namespace pdamp::surrogate {

namespace {

/// The periods that fell into one stroke bin.
struct Bin {
  double eta_sum = 0.0, eta_square_sum = 0.0, apparent_mass_sum = 0.0;
  int periods = 0;
};

}  // namespace

EffectiveField decay_field(std::span<const DecayPeriodResponse> periods, double clearance_m, double bed_mass_kg,
                           const Provenance& provenance, int bins_per_decade) {
  if (periods.size() < 3)
    throw std::invalid_argument("decay_field: " + std::to_string(periods.size()) +
                                " periods: a field needs at least two after the release");
  if (bins_per_decade < 1 || bins_per_decade > 100)
    throw std::invalid_argument("decay_field: bins_per_decade = " + std::to_string(bins_per_decade) +
                                ": must be in [1, 100]");
  const auto used = periods.subspan(1);  // the first period holds the release, not a state of the bed
  const double per_decade = bins_per_decade;
  double lowest = INFINITY, highest = 0.0, frequency_sum = 0.0;
  for (const auto& p : used) {
    if (!(p.stroke_m > 0.0 && std::isfinite(p.stroke_m) && std::isfinite(p.eta_star) &&
          std::isfinite(p.apparent_mass_fraction) && p.frequency_hz > 0.0 && std::isfinite(p.frequency_hz)))
      throw std::invalid_argument("decay_field: the period at t = " + std::to_string(p.time_s) +
                                  " s has a stroke, frequency or response that is not finite and positive");
    lowest = std::min(lowest, p.stroke_m);
    highest = std::max(highest, p.stroke_m);
    frequency_sum += p.frequency_hz;
  }
  const auto bin_of = [&](double stroke_m) { return static_cast<long>(std::floor(std::log10(stroke_m) * per_decade)); };
  const long first = bin_of(lowest);
  const long count = bin_of(highest) - first + 1;
  std::vector<Bin> bins(static_cast<std::size_t>(count));
  for (const auto& p : used) {
    Bin& b = bins[static_cast<std::size_t>(bin_of(p.stroke_m) - first)];
    b.eta_sum += p.eta_star;
    b.eta_square_sum += p.eta_star * p.eta_star;
    b.apparent_mass_sum += p.apparent_mass_fraction;
    ++b.periods;
  }

  const double frequency_hz = frequency_sum / static_cast<double>(used.size());
  EffectiveField field;
  field.grid.axis0 = {AxisQuantity::kFrequencyHz, AxisSpacing::kLinear, {0.8 * frequency_hz, 1.25 * frequency_hz}};
  field.grid.axis1.quantity = AxisQuantity::kAmplitudeM;
  field.grid.axis1.spacing = AxisSpacing::kLog;
  for (long b = 0; b < count; ++b)
    field.grid.axis1.values.push_back(std::pow(10.0, (static_cast<double>(first + b) + 0.5) / per_decade));
  field.provenance = provenance;
  field.clearance_m = clearance_m;
  field.bed_mass_kg = bed_mass_kg;

  // One node per bin: the mean of its periods; an empty bin linear between its neighbours
  // (the lowest and the highest bins hold a period each by construction).
  std::vector<FieldPoint> nodes(static_cast<std::size_t>(count));
  for (std::size_t b = 0; b < nodes.size(); ++b) {
    const Bin& bin = bins[b];
    if (bin.periods == 0) continue;
    const double n = bin.periods;
    const double mean = bin.eta_sum / n;
    const double variance = n > 1 ? std::max(bin.eta_square_sum / n - mean * mean, 0.0) * n / (n - 1.0) : 0.0;
    // A bin of a bed that barely dissipates can average slightly below 0: a period's first
    // harmonic also carries the change of the bed's own kinetic energy over the period, which
    // scatters about 0. Over many periods a passive bed gives no energy back: 0 is its floor.
    nodes[b].eta_star = std::max(mean, 0.0);
    nodes[b].eta_star_stderr = std::sqrt(variance / n);
    nodes[b].apparent_mass_fraction = bin.apparent_mass_sum / n;
    nodes[b].motion_mode = "decay";
  }
  for (std::size_t b = 0; b < nodes.size(); ++b) {
    if (bins[b].periods > 0) continue;
    std::size_t below = b, above = b;
    while (bins[below].periods == 0) --below;
    while (bins[above].periods == 0) ++above;
    const double w = static_cast<double>(b - below) / static_cast<double>(above - below);
    nodes[b].eta_star = (1.0 - w) * nodes[below].eta_star + w * nodes[above].eta_star;
    nodes[b].eta_star_stderr = std::max(nodes[below].eta_star_stderr, nodes[above].eta_star_stderr);
    nodes[b].apparent_mass_fraction =
        (1.0 - w) * nodes[below].apparent_mass_fraction + w * nodes[above].apparent_mass_fraction;
    nodes[b].motion_mode = "decay_interpolated";
  }
  for (const double f : field.grid.axis0.values) {
    const double omega = 2.0 * std::numbers::pi * f;
    for (std::size_t b = 0; b < nodes.size(); ++b) {
      FieldPoint p = nodes[b];
      const double v = field.grid.axis1.values[b] * omega;
      p.e_diss_j = formulas::dissipated_energy_measure(p.eta_star, bed_mass_kg, v);
      p.apparent_mass_kg = p.apparent_mass_fraction * bed_mass_kg;
      p.status = PointStatus::kOk;
      field.points.push_back(std::move(p));
    }
  }
  if (const auto problems = field.validate(); !problems.empty())
    throw std::invalid_argument("decay_field: " + problems.front());
  return field;
}

}  // namespace pdamp::surrogate
