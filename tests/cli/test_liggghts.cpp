// pdamp export liggghts and pdamp import liggghts (docs/liggghts.md): the deck, the import's
// conventions on a synthetic LIGGGHTS output whose answer is known, its refusals, and (when
// LIGGGHTS is installed, [long]) a real LIGGGHTS run of the shipped case against pdamp dem.
// pdamp and LIGGGHTS run through argument vectors (support/run_pdamp.hpp), never a shell.
#include <catch2/catch.hpp>
#include <functional>
#include <sstream>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

constexpr double kPi = 3.14159265358979323846;
const char* const kLiggghts = "/usr/bin/liggghts";

/// A fresh folder under the temporary directory.
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pdamp_liggghts_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

/// The shipped low-intensity case's deck with `periods` analysed periods, in `dir`.
json export_deck(const fs::path& dir, int periods) {
  const auto r = run_pdamp({"export", "liggghts", case_path("low_intensity_36_spheres.json"), "-o", dir.string(),
                            "--periods", std::to_string(periods), "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return json::parse(r.out);
}

/// What the deck's two ave/time fixes write for a container force on the bed of
/// c·v_c + m_a·a_c (a viscous damper and a rigid mass, docs/complex_power.md): the force
/// of the bed on the walls is its negative, each sample the mean over its steps, step s at
/// t = s·dt from the drive's start (LIGGGHTS' wiggle moves the mesh to X sin(Ω s dt) in
/// step s); the bed's energy and centre of mass constant.
void write_synthetic_output(const fs::path& dir, const json& record, double c_n_s_m, double mass_kg) {
  const std::string title = "# pdamp export " + record["export_id"].get<std::string>();
  const double x = record["amplitude_m"], f = record["frequency_hz"], dt = record["time_step_s"];
  const long long per_sample = record["steps_per_sample"], samples = record["samples_per_period"];
  const long long last = samples * (record["transient_periods"].get<long long>() + record["analysed_periods"].get<long long>());
  const double omega = 2.0 * kPi * f;
  std::ofstream force(dir / "force.txt"), energy(dir / "energy.txt");
  force << std::setprecision(17) << title << "\n# TimeStep f_pdamp_container[1] f_pdamp_container[2] f_pdamp_container[3]\n";
  energy << std::setprecision(17) << title << "\n# TimeStep c_pdamp_ke c_pdamp_rke c_pdamp_com[1] c_pdamp_com[2] c_pdamp_com[3]\n";
  energy << 0 << " 0.01 0.001 -0.02 0 -0.015\n";
  for (long long m = 1; m <= last; ++m) {
    double sum = 0.0;
    for (long long s = (m - 1) * per_sample + 1; s <= m * per_sample; ++s) {
      const double t = static_cast<double>(s) * dt;
      sum += -(c_n_s_m * x * omega * std::cos(omega * t) - mass_kg * x * omega * omega * std::sin(omega * t));
    }
    force << m * per_sample << " " << sum / static_cast<double>(per_sample) << " 0 0\n";
    energy << m * per_sample << " 0.01 0.001 -0.02 0 -0.015\n";
  }
}

}  // namespace

TEST_CASE("pdamp export liggghts writes the deck of pdamp dem's run", "[cli][liggghts]") {
  const fs::path dir = fresh_dir("deck");
  const json record = export_deck(dir, 2);
  for (const char* name : {"in.pdamp", "particles.data", "container.stl", "README.txt", "pdamp_export.json"})
    CHECK(fs::is_regular_file(dir / name));
  // pdamp dem's own run of the case: its time step, samples and stroke (pdamp dem --json
  // reports them; the export takes them from the same plan).
  CHECK(record["case"] == "low_intensity_36_spheres");
  CHECK(record["amplitude_m"].get<double>() == 0.04);
  CHECK(record["frequency_hz"].get<double>() == 2.0);
  CHECK(record["transient_periods"].get<int>() == 3);
  CHECK(record["analysed_periods"].get<int>() == 2);
  CHECK(record["particles"].get<int>() == 36);
  CHECK(record["drive_axis"] == "x");
  CHECK(record["steps_per_period"].get<long long>() ==
        record["samples_per_period"].get<long long>() * record["steps_per_sample"].get<long long>());
  CHECK(record["time_step_s"].get<double>() * record["steps_per_period"].get<double>() == Approx(0.5).epsilon(1e-12));
  // 36 steel spheres of at most 5 mm radius (the G100 lot: radii down to 5 mm − 2.5 µm).
  CHECK(record["bed_mass_kg"].get<double>() == Approx(36 * 4.0 / 3.0 * kPi * 1.25e-7 * 7850.0).epsilon(2e-3));
  const std::string deck = slurp(dir / "in.pdamp");
  CHECK_THAT(deck, Catch::Contains("pair_style gran model hertz tangential history tangential_damping off limitForce on"));
  CHECK_THAT(deck, Catch::Contains("wiggle amplitude 0.040000000000000001 0 0 period 0.5"));
  // Steel softened by the case's 0.01: 210 GPa x 0.01.
  CHECK_THAT(deck, Catch::Contains("youngsModulus peratomtype 2100000000"));
  CHECK_THAT(deck, Catch::Contains("title1 \"# pdamp export " + record["export_id"].get<std::string>() + "\""));
  CHECK_THAT(slurp(dir / "particles.data"), Catch::Contains("36 atoms"));
  fs::remove_all(dir);
}

TEST_CASE("pdamp import liggghts measures a synthetic damper and mass as the complex power defines them", "[cli][liggghts]") {
  const fs::path dir = fresh_dir("synthetic");
  const json record = export_deck(dir, 2);
  // A viscous damper c and a rigid mass m_a (docs/complex_power.md: η* = c/(m_bed Ω),
  // m_app = m_a): the sample means and the drive bin's step weight each scale the
  // force's harmonic by sinc(π/M), M = 1000 samples a period: 1 − sinc² = 3.3e-6.
  const double c = 0.3, mass = 0.05;
  write_synthetic_output(dir, record, c, mass);
  const auto r = run_pdamp({"import", "liggghts", dir.string(), "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  const double m_bed = record["bed_mass_kg"], omega = 2.0 * kPi * 2.0;
  CHECK(out["eta_star"].get<double>() == Approx(c / (m_bed * omega)).epsilon(1e-5));
  CHECK(out["apparent_mass_kg"].get<double>() == Approx(mass).epsilon(1e-5));
  // The container's work over the samples (time domain) is n·2π·E_diss: n·π·c·V²/Ω of the damper.
  const double v = 0.04 * omega;
  CHECK(out["energy"]["container_work_j"].get<double>() == Approx(2 * kPi * c * v * v / omega).epsilon(1e-5));
  CHECK_FALSE(out.contains("eta_star_energy_balance"));  // no counted dissipation in LIGGGHTS' output
  // Per period the same value: the standard error is round-off.
  CHECK(out["eta_star_per_period"].size() == 2);
  CHECK(out["eta_star_stderr"].get<double>() < 1e-9);
  CHECK(out["energy"]["delta_kinetic_j"].get<double>() == 0.0);
  for (const char* key : {"e_diss_j", "energy_per_cycle_j", "apparent_mass_fraction", "bed_mass_kg", "amplitude_m",
                          "frequency_hz", "intensity", "time_step_s", "steps_per_period", "clearance_m", "closed_form", "run"})
    CHECK(out.contains(key));
  // -o OUT: summary.json holds the same object.
  const fs::path summary_dir = fresh_dir("summary");
  const auto written = run_pdamp({"import", "liggghts", dir.string(), "-o", summary_dir.string(), "--json"});
  REQUIRE(written.exit_code == 0);
  CHECK(json::parse(slurp(summary_dir / "summary.json"))["eta_star"] == out["eta_star"]);
  // Not into the deck's own folder: its commit would remove the deck.
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string(), "-o", dir.string()}), "-o: ");
  fs::remove_all(summary_dir);
  fs::remove_all(dir);
}

TEST_CASE("pdamp import liggghts refuses a missing or garbled output with one line naming the file", "[cli][liggghts]") {
  const fs::path dir = fresh_dir("errors");
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "is not a folder");
  fs::create_directories(dir);
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "pdamp_export.json: missing");
  const json record = export_deck(dir, 2);
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "force.txt: missing");
  write_synthetic_output(dir, record, 0.3, 0.0);
  const std::string good = slurp(dir / "force.txt");
  const auto with_force = [&](const std::string& text) {
    std::ofstream(dir / "force.txt") << text;
    return run_pdamp({"import", "liggghts", dir.string()});
  };
  // A word where a number belongs (line 5: title, header, samples 1 and 2, then this).
  std::string garbled = good;
  const auto third = garbled.find('\n', garbled.find('\n', garbled.find('\n', garbled.find('\n') + 1) + 1) + 1);
  garbled.insert(third + 1, "300 nan 0 0\n");
  require_one_line_error(with_force(garbled), "force.txt: line 5: 'nan' is not a finite number");
  // A run that stopped early.
  const std::string half = good.substr(0, good.rfind('\n', good.size() / 2) + 1);
  require_one_line_error(with_force(half), "force.txt: holds");
  CHECK_THAT(with_force(half).err, Catch::Contains("has not finished"));
  // A file of far more rows than the run writes (once 30 M rows took 2.5 GB before they were
  // refused): refused at the first row too many, naming its line.
  std::string doubled = good;
  const std::string body = good.substr(good.find('\n', good.find('\n') + 1) + 1);  // after title and header
  for (int k = 0; k < 3; ++k) doubled += body;
  require_one_line_error(with_force(doubled), "samples of this export's run");
  // The output of an earlier deck (another export's title).
  require_one_line_error(with_force("# pdamp export 0123456789abcdef\n" + good.substr(good.find('\n') + 1)),
                         "force.txt: line 1:");
  // A record that is not JSON.
  std::ofstream(dir / "force.txt") << good;
  std::ofstream(dir / "pdamp_export.json") << "{\"format\": ";
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "pdamp_export.json: malformed JSON");
  fs::remove_all(dir);
}

TEST_CASE("pdamp export liggghts takes a user time step above the automatic bound as pdamp dem does", "[cli][liggghts]") {
  // Full stiffness at 1 us: above the automatic bound at 50 steps per contact (given), below
  // the stability limit (20 steps, the Rayleigh time): pdamp dem runs it with a warning, so
  // the export must write it, with the same warning, not refuse it.
  const auto stepped = edited_case("pdamp_liggghts_step.json", [](json& c) {
    c["dem"]["stiffness_softening"] = 1.0;
    c["dem"]["time_step_s"] = 1e-6;
    c["dem"]["steps_per_contact"] = 50;
  });
  const fs::path dir = fresh_dir("step");
  const auto r = run_pdamp({"export", "liggghts", stepped, "-o", dir.string(), "--periods", "1", "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(json::parse(r.out)["time_step_s"].get<double>() == 1e-6);
  CHECK_THAT(r.err, Catch::Contains("steps per contact"));
  CHECK_THAT(slurp(dir / "in.pdamp"), Catch::Contains("timestep 9.9999999999999995e-07"));
  fs::remove_all(dir);
}

TEST_CASE("pdamp export liggghts refuses what LIGGGHTS cannot run as pdamp does, before writing", "[cli][liggghts]") {
  const fs::path dir = fresh_dir("refused");
  const auto layered = edited_case("pdamp_liggghts_layer.json", [](json& c) {
    c["materials"]["pu"] = {{"density_kg_m3", 1200}, {"youngs_modulus_pa", 60e6}, {"poisson_ratio", 0.48}};
    c["dem"]["wall_layer"] = {{"thickness_m", 0.0005}, {"material", "pu"}, {"axis", "x"}};
  });
  require_one_line_error(run_pdamp({"export", "liggghts", layered, "-o", dir.string()}), "/dem/wall_layer: ");
  const auto table = edited_case("pdamp_liggghts_table.json", [](json& c) {
    c["dem"]["contact"]["restitution"] = {{"speeds_m_s", {0.0, 1.0}}, {"values", {0.9, 0.7}}};
  });
  require_one_line_error(run_pdamp({"export", "liggghts", table, "-o", dir.string()}), "/dem/contact/restitution: ");
  require_one_line_error(run_pdamp({"export", "liggghts", case_path("low_intensity_36_spheres.json")}), "-o: required");
  CHECK_FALSE(fs::exists(dir));
}

// LIGGGHTS and pdamp on the shipped 36-sphere case (E/100, X = 0.04 m at 2 Hz: rolling
// collect-and-collide), 3 transient and 6 analysed periods each.
TEST_CASE("a LIGGGHTS run of the exported deck gives pdamp dem's eta*", "[cli][liggghts][long]") {
  if (!fs::exists(kLiggghts)) {
    WARN("SKIP: " << kLiggghts << " is not installed (Debian package liggghts); the LIGGGHTS comparison did not run");
    return;
  }
  const int periods = 6;
  const fs::path dir = fresh_dir("run");
  export_deck(dir, periods);
  const auto started = std::chrono::steady_clock::now();
  const auto liggghts = run_program({kLiggghts, "-in", "in.pdamp"}, RunOptions{dir, 600.0, {}, {}, 0});
  const double liggghts_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  INFO(liggghts.out.substr(liggghts.out.size() > 2000 ? liggghts.out.size() - 2000 : 0) << liggghts.err);
  REQUIRE(liggghts.exit_code == 0);
  const auto imported = run_pdamp({"import", "liggghts", dir.string(), "--json"});
  INFO(imported.err);
  REQUIRE(imported.exit_code == 0);
  const json l = json::parse(imported.out);
  const auto dem = run_pdamp({"dem", case_path("low_intensity_36_spheres.json"), "--periods", std::to_string(periods), "--json"});
  REQUIRE(dem.exit_code == 0);
  const json p = json::parse(dem.out);
  const double eta_l = l["eta_star"], eta_p = p["eta_star"];
  const double se_l = l["eta_star_stderr"], se_p = p["eta_star_stderr"];
  WARN("eta* LIGGGHTS " << eta_l << " +- " << se_l << " (" << liggghts_s << " s), pdamp " << eta_p << " +- " << se_p << " ("
                        << p["run"]["wall_time_s"].get<double>() << " s)");
  // Tolerance: 10% or two combined standard errors, whichever is larger. The codes share
  // the geometry, the bed's start, E, ν, ρ, μ, the time step and the drive, but not the
  // normal damping: pdamp calibrates γ_n so that one impact realises the case's ε = 0.8
  // exactly (docs/dem.md), LIGGGHTS' hertz model takes the damping ratio β of the linear
  // spring-dashpot (the Tsuji form, damping ∝ δ^{1/4}, with β = ln ε/√(ln²ε + π²)), which
  // on a Hertz contact realises ε = 0.808 for the case's 0.8 (pdamp's one-impact integral
  // of LIGGGHTS' law, liggghts_realised_restitution in pdamp_export.json); their rolling
  // laws differ too (pdamp's elastic-plastic spring against cdt's constant torque; this
  // case has none), the two integrators' round-off makes the chaotic bed's paths part
  // within periods, and the per-period η* of this bed scatters by about 10% (its standard
  // error over 6 periods is about 4% of η*), so no closer agreement can be asked.
  const double tolerance = std::max(0.10 * std::abs(eta_p), 2.0 * std::sqrt(se_l * se_l + se_p * se_p));
  CHECK(std::abs(eta_l - eta_p) <= tolerance);
  // The container's work over the analysis is the drive bin's n·2π·E_diss (the same
  // samples in the time domain; 1e-13 measured, 1e-6 allowed for the 6-digit samples).
  CHECK(l["energy"]["container_work_j"].get<double>() ==
        Approx(periods * l["energy_per_cycle_j"].get<double>()).epsilon(1e-6));
  fs::remove_all(dir);
}

// Reference: the case's own ranges and the export's own form for what pdamp_export.json
// says, and finite results or the input file named (once: η* silently 0 or doubled, a force
// measured along another axis, `null` in the JSON with exit 0, or a raw library message).
TEST_CASE("pdamp import liggghts refuses an edited record and outputs that overflow, naming the file", "[cli][liggghts]") {
  const fs::path dir = fresh_dir("ranges");
  const json record = export_deck(dir, 2);
  write_synthetic_output(dir, record, 0.3, 0.0);
  const std::string good_record = slurp(dir / "pdamp_export.json");
  const auto with_record = [&](const std::function<void(json&)>& edit) {
    json r = json::parse(good_record);
    edit(r);
    std::ofstream(dir / "pdamp_export.json") << r.dump(2);
    return run_pdamp({"import", "liggghts", dir.string()});
  };
  REQUIRE(with_record([](json&) {}).exit_code == 0);
  require_one_line_error(with_record([](json& r) { r["amplitude_m"] = 1e300; }), "pdamp_export.json: /amplitude_m: = 1e+300");
  require_one_line_error(with_record([](json& r) { r["bed_mass_kg"] = 1e-320; }), "/bed_mass_kg: = ");
  require_one_line_error(with_record([](json& r) { r["gravity_m_s2"] = {0.0, 0.0, -1e300}; }), "/gravity_m_s2: = -1e+300");
  for (const json& direction : {json{0.0, 0.0, 0.0}, json{2.0, 0.0, 0.0}, json{0.0, 1.0, 0.0}})
    require_one_line_error(with_record([&](json& r) { r["drive_direction"] = direction; }),
                           "/drive_direction: must be the unit vector of drive_axis x");
  require_one_line_error(with_record([](json& r) { r["settling_steps"] = "x"; }), "/settling_steps: must be a number, got string");
  std::ofstream(dir / "pdamp_export.json") << good_record;

  // Energies near the largest double: their balance overflows.
  const std::string good_energy = slurp(dir / "energy.txt");
  std::string huge = good_energy;
  for (std::size_t at = huge.find(" 0.01 0.001 "); at != std::string::npos; at = huge.find(" 0.01 0.001 ", at + 1))
    huge.replace(at, 12, " 1.7e308 1.7e308 ");  // kinetic + rotational: +inf at both ends
  std::ofstream(dir / "energy.txt") << huge;
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "energy.txt: its energies give a non-finite");
  std::ofstream(dir / "energy.txt") << good_energy;
  // A force of 1e11 N in one sample (η* far beyond any bed's), and forces of 1.7e308 N that
  // would overflow the sums: named by their file, not by the library that overflowed.
  const std::string good_forces = slurp(dir / "force.txt");
  std::string forces = good_forces;
  const std::size_t line = forces.rfind('\n', forces.size() - 2) + 1;  // the last sample (analysed)
  const std::size_t value = forces.find(' ', line) + 1;
  forces.replace(value, forces.find(' ', value) - value, "1e11");
  std::ofstream(dir / "force.txt") << forces;
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "force.txt: its forces give eta_star = ");
  std::string overflowing = good_forces;
  // Every sample's force component along x becomes 1.7e308 (each line "step fx 0 0").
  for (std::size_t at = overflowing.find(" 0 0\n"); at != std::string::npos;) {
    const std::size_t start = overflowing.rfind(' ', at - 1) + 1;
    overflowing.replace(start, at - start, "1.7e308");
    at = overflowing.find(" 0 0\n", start + 7 + 5);  // past this line
  }
  std::ofstream(dir / "force.txt") << overflowing;
  require_one_line_error(run_pdamp({"import", "liggghts", dir.string()}), "beyond any bed's (1e12 N)");
  fs::remove_all(dir);
}

// Reference: LIGGGHTS' own limits (its run command takes at most 2^31 − 1 steps; atom types
// must start from 1). A drive of 7.4e9 steps is written as consecutive runs of at most
// 2^31 − 1 that add up to it (once: `run 7384805604`, which LIGGGHTS refuses).
TEST_CASE("pdamp export liggghts splits a run beyond LIGGGHTS' 2^31 - 1 steps", "[cli][liggghts]") {
  const auto long_case = edited_case("pdamp_liggghts_long.json", [](json& c) {
    c["dem"]["samples_per_period"] = 16;
    c["dem"]["steps_per_contact"] = 50;  // the 7.4e9 steps below
  });
  const fs::path dir = fresh_dir("long_run");
  const auto r = run_pdamp({"export", "liggghts", long_case, "-o", dir.string(), "--periods", "50000", "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json record = json::parse(r.out);
  const long long drive = record["steps_per_period"].get<long long>() *
                          (record["transient_periods"].get<long long>() + record["analysed_periods"].get<long long>());
  REQUIRE(drive > 2147483647LL);
  const std::string deck = slurp(dir / "in.pdamp");
  // The drive's runs follow reset_timestep 0; the settling run comes before it.
  std::istringstream lines(deck.substr(deck.find("reset_timestep 0")));
  long long total = 0;
  int runs = 0;
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("run ", 0) == 0) {
      const long long steps = std::stoll(line.substr(4));
      CHECK(steps >= 1);
      CHECK(steps <= 2147483647LL);
      total += steps;
      ++runs;
    }
  CHECK(runs == 4);
  CHECK(total == drive);
  fs::remove_all(dir);
}

// A bed of another material than the built-in steel walls (tungsten sorts after steel): the
// deck's types are the materials in use, the spheres type 1 (once the spheres were type 2
// and LIGGGHTS stopped: "Atom types must start from 1"). LIGGGHTS runs one period of it.
TEST_CASE("LIGGGHTS runs the deck of a tungsten bed in steel walls", "[cli][liggghts][long]") {
  const auto tungsten = edited_case("pdamp_liggghts_tungsten.json", [](json& c) {
    c["materials"] = {{"tungsten", {{"density_kg_m3", 19250}, {"youngs_modulus_pa", 411e9}, {"poisson_ratio", 0.28}}},
                      {"unused", {{"density_kg_m3", 1000}, {"youngs_modulus_pa", 1e9}, {"poisson_ratio", 0.3}}}};
    c["damper"]["particles"]["material"] = "tungsten";
    c["dem"]["transient_periods"] = 0;
  });
  const fs::path dir = fresh_dir("tungsten");
  const auto r = run_pdamp({"export", "liggghts", tungsten, "-o", dir.string(), "--periods", "1"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(slurp(dir / "particles.data"), Catch::Contains("2 atom types"));
  if (!fs::exists(kLiggghts)) {
    WARN("SKIP: " << kLiggghts << " is not installed (Debian package liggghts); the deck did not run");
    return;
  }
  const auto liggghts = run_program({kLiggghts, "-in", "in.pdamp"}, RunOptions{dir, 600.0, {}, {}, 0});
  INFO(liggghts.out.substr(liggghts.out.size() > 2000 ? liggghts.out.size() - 2000 : 0) << liggghts.err);
  REQUIRE(liggghts.exit_code == 0);
  const auto imported = run_pdamp({"import", "liggghts", dir.string(), "--json"});
  INFO(imported.err);
  CHECK(imported.exit_code == 0);
  fs::remove_all(dir);
}

// Reference: what a folder, a flag or a case's name can do to the export and the import
// (once: exit 1 with a raw "filesystem error" for a loop of symbolic links, `-o=DIR` refused
// although long flags take '=', a newline and a terminal escape of the case's name printed
// raw to stdout and README.txt).
TEST_CASE("pdamp export and import liggghts take -o=DIR, refuse symlink loops and print a name escaped", "[cli][liggghts]") {
  const fs::path dir = fresh_dir("links");
  fs::create_directories(dir);
  const auto named = edited_case("pdamp_liggghts_named.json", [](json& c) { c["name"] = "two\nlines\x1b[31m"; });
  const auto r = run_pdamp({"export", "liggghts", named, "-o=" + (dir / "deck").string(), "--periods", "1"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(fs::is_regular_file(dir / "deck" / "in.pdamp"));
  CHECK(r.out.find('\x1b') == std::string::npos);
  CHECK_THAT(r.out, Catch::Contains("two\\nlines\\x1b[31m"));
  const std::string readme = slurp(dir / "deck" / "README.txt");
  CHECK(readme.find('\x1b') == std::string::npos);
  CHECK_THAT(readme, Catch::Contains("two\\nlines"));
  // A loop of symbolic links at force.txt, and at the folder itself.
  fs::create_symlink("loop_b", dir / "deck" / "force.txt");
  fs::create_symlink("force.txt", dir / "deck" / "loop_b");
  require_one_line_error(run_pdamp({"import", "liggghts", (dir / "deck").string()}),
                         "force.txt: cannot be read: Too many levels of symbolic links");
  fs::create_symlink("b", dir / "a");
  fs::create_symlink("a", dir / "b");
  require_one_line_error(run_pdamp({"import", "liggghts", (dir / "a").string()}), "cannot be read");
  fs::remove_all(dir);
}
