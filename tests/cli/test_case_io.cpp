// Command-line contract (docs/command_line.md): exit codes, one-line errors naming file,
// key and range, --json keys, atomic -o output. Runs the built pdamp binary (through
// an argument vector, support/run_pdamp.hpp).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

TEST_CASE("shipped cases validate and report the collected bed's clearance", "[cli]") {
  const auto r = run_pdamp("validate " + case_path("low_intensity_36_spheres.json"));
  REQUIRE(r.exit_code == 0);
  const json resolved = json::parse(r.out);
  // 160 mm inner length minus 6 slabs of 10 mm spheres (docs/theory.md §9, clearance of a real bed).
  CHECK(resolved["damper"]["derived"]["clearance_m"].get<double>() == Approx(0.100).margin(1e-12));
  // 36 steel spheres of 5 mm radius: 36 * 4/3 pi r^3 * 7850 kg/m^3.
  CHECK(resolved["damper"]["derived"]["bed_mass_kg"].get<double>() ==
        Approx(36 * 4.0 / 3.0 * kPi * 1.25e-7 * 7850.0).epsilon(1e-12));
  CHECK(resolved["damper"]["model_options"]["rolling_calibration"].get<double>() == Approx(0.8976));
  for (const char* name : {"high_intensity_cylinder.json", "buffered_wall_60hz.json"})
    CHECK(run_pdamp(std::string("validate ") + case_path(name)).exit_code == 0);
}

TEST_CASE("malformed JSON is a one-line error naming the file", "[cli]") {
  const fs::path path = fs::temp_directory_path() / "pdamp_malformed.json";
  std::ofstream(path) << "{ \"name\": \"x\", ";
  require_one_line_error(run_pdamp("validate " + path.string()), "pdamp_malformed.json: malformed JSON");
}

TEST_CASE("unknown keys are rejected with their JSON pointer", "[cli]") {
  const auto path = edited_case("pdamp_unknown_key.json", [](json& c) { c["damper"]["particles"]["radus_m"] = 0.005; });
  require_one_line_error(run_pdamp("validate " + path), "/damper/particles/radus_m: unknown key");
}

TEST_CASE("a negative radius names the key and the allowed range", "[cli]") {
  const auto path = edited_case("pdamp_negative_radius.json", [](json& c) { c["damper"]["particles"]["radius_m"] = -0.005; });
  require_one_line_error(run_pdamp("validate " + path), "/damper/particles/radius_m: = -0.005: must be a finite number >= 1e-05 and <= 1");
}

TEST_CASE("particles that do not fit are rejected with the numbers", "[cli]") {
  const auto path = edited_case("pdamp_no_fit.json", [](json& c) { c["damper"]["particles"]["count"] = 500; });
  require_one_line_error(run_pdamp("validate " + path), "/damper/particles");
}

TEST_CASE("wrong types are rejected", "[cli]") {
  const auto path = edited_case("pdamp_wrong_type.json", [](json& c) { c["excitation"]["frequency_hz"] = "2"; });
  require_one_line_error(run_pdamp("validate " + path), "/excitation/frequency_hz: must be a number");
}

TEST_CASE("bad flags are rejected: negative clearance and zero amplitude and unknown model and non-numbers", "[cli]") {
  require_one_line_error(run_pdamp("loss --model rolling --clearance -0.1 --amplitude 0.04 --frequency 2"),
                         "--clearance: '-0.1': must be a finite number >= 1e-06 and <= 100");
  require_one_line_error(run_pdamp("loss --model rolling --clearance 0.1 --amplitude 0 --frequency 2"),
                         "--amplitude: '0': must be a finite number >= 1e-07 and <= 10");
  require_one_line_error(run_pdamp("loss --model sliding --clearance 0.1 --amplitude 0.04 --frequency 2"),
                         "--model: 'sliding' is not a model here");
  require_one_line_error(run_pdamp("optimum --model rolling --clearance nan"), "--clearance");
  require_one_line_error(run_pdamp("optimum --model rolling --clearance 0.1 --colour red"), "--colour: unknown option");
  require_one_line_error(run_pdamp("optimum --model rolling"), "--clearance: required");
  require_one_line_error(run_pdamp("frobnicate"), "frobnicate: unknown command");
}

TEST_CASE("json output is exactly one object with the promised keys", "[cli]") {
  const auto optimum = run_pdamp("optimum --model rolling --clearance 0.1 --json");
  REQUIRE(optimum.exit_code == 0);
  const json o = json::parse(optimum.out);
  for (const char* key : {"model", "clearance_m", "x_opt_m", "x_opt_ideal_m", "x_onset_m"}) CHECK(o.contains(key));
  // Calibrated design value 0.4 h_roll (docs/theory.md §3).
  CHECK(o["x_opt_m"].get<double>() == Approx(0.04).epsilon(1e-4));

  const auto size = run_pdamp("size --model bouncing --stroke 0.01 --json");
  REQUIRE(size.exit_code == 0);
  const json s = json::parse(size.out);
  for (const char* key : {"model", "stroke_m", "clearance_m"}) CHECK(s.contains(key));
  CHECK(s["clearance_m"].get<double>() == Approx(0.01 * kPi).epsilon(1e-12));  // X_opt = h/pi

  const auto loss = run_pdamp("loss --model bouncing --clearance 0.01 --amplitude 0.005 --frequency 50 --bed-mass 2 --json");
  REQUIRE(loss.exit_code == 0);
  const json l = json::parse(loss.out);
  for (const char* key : {"eta_star", "e_diss_j", "energy_per_cycle_j", "regime", "warnings"}) CHECK(l.contains(key));
  // X = h/2: eta* = (1 - cos phi*)^2/pi = 1.0685 (docs/theory.md §2); E_diss = eta* m V^2/2.
  const double v = 0.005 * 2 * kPi * 50;
  CHECK(l["eta_star"].get<double>() == Approx(1.0685).epsilon(1e-3));
  CHECK(l["e_diss_j"].get<double>() == Approx(l["eta_star"].get<double>() * 0.5 * 2.0 * v * v).epsilon(1e-12));

  const auto buffer = run_pdamp("buffer --frequency 60 --intensity 20 --radius 0.0025 --layer-modulus 60e6 --json");
  REQUIRE(buffer.exit_code == 0);
  const json b = json::parse(buffer.out);
  for (const char* key : {"layer_thickness_m", "impact_velocity_m_s", "max_penetration_m", "contact_time_s"})
    CHECK(b.contains(key));
}

TEST_CASE("validity warnings go to stderr and into the JSON warnings list", "[cli]") {
  // Rolling at Gamma = 0.16*(2 pi 5)^2/g = 16 is far outside its range (A < g).
  const auto r = run_pdamp("loss --model rolling --clearance 0.1 --amplitude 0.16 --frequency 5 --json");
  REQUIRE(r.exit_code == 0);
  const json l = json::parse(r.out);
  REQUIRE(!l["warnings"].empty());
  CHECK_THAT(r.err, Catch::Contains("pdamp: warning: "));
}

TEST_CASE("run writes its results atomically into the output directory", "[cli]") {
  const fs::path dir = fs::temp_directory_path() / "pdamp_run_out";
  fs::remove_all(dir);
  const auto r = run_pdamp("run " + case_path("low_intensity_36_spheres.json") + " -o " + dir.string() + " --json");
  REQUIRE(r.exit_code == 0);
  const json result = json::parse(r.out);
  CHECK(result["task"] == "damper_design");
  CHECK(result["outputs"].size() >= 3);
  for (const char* name : {"design.json", "eta_curve.csv", "case_resolved.json"}) CHECK(fs::exists(dir / name));
  for (const auto& entry : fs::directory_iterator(dir))
    CHECK(entry.path().filename().string().rfind(".pdamp-staging", 0) != 0);

  // A bad case writes nothing.
  const fs::path bad_dir = fs::temp_directory_path() / "pdamp_run_bad";
  fs::remove_all(bad_dir);
  const auto path = edited_case("pdamp_bad_run.json", [](json& c) { c["excitation"]["frequency_hz"] = -1.0; });
  CHECK(run_pdamp("run " + path + " -o " + bad_dir.string()).exit_code == 2);
  CHECK(!fs::exists(bad_dir));
}

TEST_CASE("pdamp dem needs a stroke and rejects unknown dem keys", "[cli]") {
  const auto no_amplitude = edited_case("pdamp_dem_no_x.json", [](json& c) { c["excitation"].erase("amplitude_m"); });
  require_one_line_error(run_pdamp("dem " + no_amplitude), "/excitation/amplitude_m: required by pdamp dem");
  const auto unknown = edited_case("pdamp_dem_unknown.json", [](json& c) { c["dem"]["time_stepp_s"] = 1e-6; });
  require_one_line_error(run_pdamp("validate " + unknown), "/dem/time_stepp_s: unknown key");
  const auto bad_cor = edited_case("pdamp_dem_cor.json", [](json& c) { c["dem"]["contact"]["restitution"] = 1.5; });
  require_one_line_error(run_pdamp("validate " + bad_cor), "/dem/contact/restitution");
}

TEST_CASE("pdamp dem reports the promised keys and writes its files", "[cli]") {
  // Softened stiffness and one period keep this a unit test (about 2 million
  // particle-steps); the physics of the run is checked in tests/dem_reference.
  const auto path = edited_case("pdamp_dem_quick.json", [](json& c) {
    c["dem"] = {{"stiffness_softening", 1e-3}, {"transient_periods", 0}, {"analysed_periods", 1}, {"snapshots", 1}};
  });
  const fs::path dir = fs::temp_directory_path() / "pdamp_dem_out";
  fs::remove_all(dir);
  const auto r = run_pdamp("dem " + path + " -o " + dir.string() + " --json");
  REQUIRE(r.exit_code == 0);
  const json d = json::parse(r.out);
  for (const char* key : {"eta_star", "eta_star_stderr", "e_diss_j", "apparent_mass_kg", "energy_balance_error",
                          "particle_steps_per_s", "motion_mode", "clearance_m"})
    CHECK(d.contains(key));
  // The DEM's own energy account closes to its target (< 2%).
  CHECK(d["energy_balance_error"].get<double>() < 0.02);
  CHECK(d["clearance_m"].get<double>() == Approx(0.100).margin(1e-9));
  for (const char* name : {"summary.json", "time_series.csv", "particles.pvd", "particles_0000.vtp"}) CHECK(fs::exists(dir / name));
  // --snapshots overrides the case's count, within its range.
  require_one_line_error(run_pdamp("dem " + path + " --snapshots 10001"), "--snapshots: '10001': must be a whole number in [0, 10000]");
}

// Every shipped case runs in the DEM as shipped ("pdamp dem on the shipped cases
// works"), closes its energy account (< 2%) and sees the clearance that the closed forms
// of `pdamp run` use (the buffered case: the clearance between the layers). About 25 s.
TEST_CASE("pdamp dem runs every shipped case as shipped", "[cli][long]") {
  for (const char* name : {"low_intensity_36_spheres.json", "high_intensity_cylinder.json", "buffered_wall_60hz.json"}) {
    INFO(name);
    const auto v = run_pdamp(std::string("validate ") + case_path(name));
    REQUIRE(v.exit_code == 0);
    const double clearance = json::parse(v.out)["damper"]["derived"]["clearance_m"].get<double>();
    const auto r = run_pdamp(std::string("dem ") + case_path(name) + " --json");
    REQUIRE(r.exit_code == 0);
    const json d = json::parse(r.out);
    CHECK(d["energy_balance_error"].get<double>() < 0.02);
    CHECK(std::isfinite(d["eta_star"].get<double>()));
    // Case geometry given to 10 µm: the lattice and layer thicknesses round below that.
    CHECK(d["clearance_m"].get<double>() == Approx(clearance).margin(1e-5));
  }
}

TEST_CASE("pdamp field from the formulas writes a readable field with the promised keys", "[cli]") {
  const auto path = edited_case("pdamp_field_case.json", [](json& c) {
    c["field"] = {{"axis0", {{"min", 1.5}, {"max", 2.5}, {"count", 3}}},
                  {"axis1", {{"min", 0.01}, {"max", 0.08}, {"count", 8}, {"spacing", "log"}}}};
  });
  const fs::path dir = fs::temp_directory_path() / "pdamp_field_out";
  fs::remove_all(dir);
  const auto r = run_pdamp("field " + path + " --source formulas -o " + dir.string() + " --json");
  REQUIRE(r.exit_code == 0);
  const json f = json::parse(r.out);
  CHECK(f["source"] == "formulas");
  CHECK(f["points"] == 24);
  REQUIRE(fs::exists(f["file"].get<std::string>()));
  std::ifstream in(f["file"].get<std::string>());
  const json field = json::parse(in);
  CHECK(field.dump().find("\"formulas\"") != std::string::npos);  // provenance names the source

  require_one_line_error(run_pdamp("field " + path + " --source magic -o " + dir.string()), "--source: 'magic'");
  const auto bad_axis = edited_case("pdamp_field_bad.json", [](json& c) {
    c["field"] = {{"axis1", {{"min", 0.05}, {"max", 0.01}, {"count", 4}}}};
  });
  require_one_line_error(run_pdamp("validate " + bad_axis), "/field/axis1/max: must be > min");
}

TEST_CASE("loss takes a scattered-fit file and rejects a bad one", "[cli]") {
  const fs::path fit = fs::temp_directory_path() / "pdamp_scattered_fit.json";
  std::ofstream(fit) << R"({"format": "pdamp.scattered_fit", "format_version": 1, "jump_fraction": 0.25,
    "exponent": 1.0, "s_min": 0.2, "s_max": 0.95, "source": "test", "residual": 1.1})";
  const auto r = run_pdamp("loss --model rolling --clearance 0.1 --amplitude 0.03 --frequency 2 --json --scattered-fit " +
                           fit.string());
  REQUIRE(r.exit_code == 0);
  const json l = json::parse(r.out);
  // Independent value: 0.25 * eta*_onset(rolling) * s, eta*_onset = 4 pi/((pi^2+4)(7/5)),
  // s = X/X_onset with X_onset = (7/5) h/sqrt(pi^2+4) (docs/theory.md §3, §4).
  const double onset = 1.4 * 0.1 / std::sqrt(kPi * kPi + 4.0);
  const double eta_onset = 4.0 * kPi / ((kPi * kPi + 4.0) * 1.4);
  CHECK(l["eta_star"].get<double>() == Approx(0.25 * eta_onset * 0.03 / onset).epsilon(1e-9));
  CHECK(l["regime"] == "scattered");

  std::ofstream(fit) << R"({"jump_fraction": 2.0})";
  require_one_line_error(run_pdamp("loss --model rolling --clearance 0.1 --amplitude 0.03 --frequency 2 --scattered-fit " +
                                   fit.string()),
                         "--scattered-fit");
}

TEST_CASE("pdamp field imports a measured field and rejects a broken CSV", "[cli]") {
  const fs::path csv = fs::temp_directory_path() / "pdamp_measured.csv";
  std::ofstream(csv) << "# rig data\nfrequency_hz,amplitude_m,eta_star,eta_star_stderr\n"
                        "2,0.02,0.10,0.02\n2,0.04,0.80,0.05\n2,0.06,0.70,0.04\n"
                        "3,0.02,0.12,0.02\n3,0.04,0.75,0.05\n3,0.06,0.66,0.04\n";
  const fs::path dir = fs::temp_directory_path() / "pdamp_measured_out";
  fs::remove_all(dir);
  const auto r = run_pdamp("field " + case_path("low_intensity_36_spheres.json") + " --source measured --measured " +
                           csv.string() + " -o " + dir.string() + " --json");
  REQUIRE(r.exit_code == 0);
  const json f = json::parse(r.out);
  CHECK(f["source"] == "measured");
  CHECK(f["points"] == 6);
  CHECK(fs::exists(dir / "field.json"));

  std::ofstream(csv) << "frequency_hz,amplitude_m,eta_star\n2,0.02,0.1\n2,0.04,abc\n";
  const auto bad = run_pdamp("field " + case_path("low_intensity_36_spheres.json") + " --source measured --measured " +
                             csv.string() + " -o " + dir.string());
  require_one_line_error(bad, "pdamp_measured.csv: line 3");
}

TEST_CASE("a DEM instability exits with code 3 and advice and a refused time step with code 2", "[cli]") {
  // An overlap limit of 1e-9 of the radius is exceeded by the first contact of the
  // settled bed: the run stops as unstable (docs/command_line.md exit code 3).
  const auto unstable = edited_case("pdamp_dem_unstable.json", [](json& c) {
    c["dem"] = {{"stiffness_softening", 1e-3}, {"max_overlap_fraction", 1e-9}, {"transient_periods", 0},
                {"analysed_periods", 1}};
  });
  const auto r = run_pdamp("dem " + unstable + " -o " + (fs::temp_directory_path() / "pdamp_unstable_out").string());
  CHECK(r.exit_code == 3);
  CHECK(r.out.empty());
  CHECK_THAT(r.err, Catch::Contains("pdamp: error: DEM unstable"));
  // The advice names the case's keys, not the library's options.
  CHECK_THAT(r.err, Catch::Contains("lower /dem/time_step_s"));
  CHECK(!fs::exists(fs::temp_directory_path() / "pdamp_unstable_out" / "summary.json"));

  const auto big_step = edited_case("pdamp_dem_step.json", [](json& c) { c["dem"] = {{"time_step_s", 1e-3}}; });
  const auto s = run_pdamp("dem " + big_step);
  CHECK(s.exit_code == 2);
  CHECK_THAT(s.err, Catch::Contains("pdamp_dem_step.json: /dem/time_step_s: = 0.001: must be <="));
}

TEST_CASE("loss says which bed mass its energies are for", "[cli]") {
  const auto r = run_pdamp("loss --model bouncing --clearance 0.01 --amplitude 0.005 --frequency 50 --json");
  REQUIRE(r.exit_code == 0);
  const json l = json::parse(r.out);
  bool said = false;
  for (const auto& w : l["warnings"]) said = said || w.get<std::string>().find("1 kg bed") != std::string::npos;
  CHECK(said);
  CHECK_THAT(r.err, Catch::Contains("no --bed-mass given"));
  const auto with_mass = run_pdamp("loss --model bouncing --clearance 0.01 --amplitude 0.005 --frequency 50 --bed-mass 2 --json");
  CHECK(with_mass.err.find("no --bed-mass") == std::string::npos);
}

TEST_CASE("a partial scattered-state fit in a case stays provisional", "[cli]") {
  const auto source_of = [](const std::function<void(json&)>& edit) {
    const auto r = run_pdamp("validate " + edited_case("pdamp_scattered.json", edit));
    REQUIRE(r.exit_code == 0);
    return json::parse(r.out)["damper"]["model_options"]["scattered"]["source"].get<std::string>();
  };
  // Only s_min given: both coefficients are the provisional defaults.
  CHECK(source_of([](json& c) { c["damper"]["model_options"] = {{"scattered", {{"s_min", 0.2}}}}; }) ==
        "provisional default");
  CHECK(source_of([](json& c) {
          c["damper"]["model_options"] = {{"scattered", {{"jump_fraction", 0.3}, {"exponent", 1.5}}}};
        }) == "case file");
}

TEST_CASE("buffer sizes a bonded layer by default and keeps the half-space rule on request", "[cli]") {
  const std::string base = "buffer --frequency 60 --intensity 20 --radius 0.0025 --layer-modulus 60e6 "
                           "--particles-per-contact 20 --layer-poisson 0.45 --json";
  const auto layered = run_pdamp(base);
  REQUIRE(layered.exit_code == 0);
  const json l = json::parse(layered.out);
  CHECK(l["model"] == "layered");
  // Sized to the default allowable strain 0.3: 0.798 mm (docs/hertz_and_buffer.md), its
  // tip strain δ_max/t the allowable one.
  CHECK(l["allowable_strain"].get<double>() == 0.3);
  CHECK(l["layer_thickness_m"].get<double>() == Approx(0.000798).epsilon(2e-3));
  CHECK(l["max_penetration_m"].get<double>() / l["layer_thickness_m"].get<double>() == Approx(0.3).epsilon(1e-9));
  // The half-space rule's 0.378 mm (the old design) is reported beside it; a layer bonded
  // to steel is stiffer, so the layer the design impact bottoms out (--allowable-strain 1)
  // is thinner, and the half-space design is compressed only partly (0.4 t in the elastic
  // foundation limit).
  CHECK(l["half_space_thickness_m"].get<double>() == Approx(0.000378).epsilon(0.01));
  const auto full = run_pdamp(base + " --allowable-strain 1");
  REQUIRE(full.exit_code == 0);
  const json f = json::parse(full.out);
  CHECK(f["layer_thickness_m"].get<double>() < 0.5 * f["half_space_thickness_m"].get<double>());
  CHECK(f["max_penetration_m"].get<double>() == Approx(f["layer_thickness_m"].get<double>()).epsilon(1e-9));
  CHECK(l["layered_compression_of_half_space_design"].get<double>() < 0.6);
  require_one_line_error(run_pdamp(base + " --allowable-strain 1.5"),
                         "--allowable-strain: '1.5': must be a finite number > 0 and <= 1");
  const auto half_space = run_pdamp(base + " --layer-model half_space");
  REQUIRE(half_space.exit_code == 0);
  const json h = json::parse(half_space.out);
  CHECK(h["layer_thickness_m"].get<double>() == Approx(h["half_space_thickness_m"].get<double>()).epsilon(1e-12));
  CHECK_THAT(half_space.err, Catch::Contains("times the layer thickness"));
  require_one_line_error(run_pdamp(base + " --layer-model winkler"), "--layer-model: 'winkler': must be layered or half_space");
  // Incompressible polyurethane is a valid layer.
  CHECK(run_pdamp("buffer --frequency 60 --intensity 20 --radius 0.0025 --layer-modulus 60e6 --layer-poisson 0.5 --json")
            .exit_code == 0);
}

TEST_CASE("the gap between lanes and the ball-lot tolerance are case keys", "[cli]") {
  const auto clearance_of = [](const std::function<void(json&)>& edit) {
    const auto r = run_pdamp("validate " + edited_case("pdamp_lanes.json", edit));
    REQUIRE(r.exit_code == 0);
    return json::parse(r.out)["damper"]["derived"]["clearance_m"].get<double>();
  };
  // 61 mm across the drive: 6 lanes of 10 mm touch (1 mm left over); "auto" shares the
  // millimetre out and keeps 6 lanes, so the 36 spheres still make 6 slabs: h = 160 − 60 mm.
  CHECK(clearance_of([](json& c) { c["damper"]["particles"]["lane_gap_m"] = "auto"; }) == Approx(0.100).margin(1e-12));
  // A 2 mm gap: 6 lanes need 6 x 10 + 5 x 2 = 70 mm > 61 mm, so the case's 6 x 6 lattice
  // is refused with the numbers; 5 lanes (58 mm) fit, and validate builds that DEM bed.
  require_one_line_error(
      run_pdamp("validate " + edited_case("pdamp_lanes_6.json", [](json& c) { c["damper"]["particles"]["lane_gap_m"] = 0.002; })),
      "6 lanes need 0.07 m along axis 1");
  CHECK(clearance_of([](json& c) {
          c["damper"]["particles"]["lane_gap_m"] = 0.002;
          c["damper"]["particles"]["count"] = 30;
          c["damper"]["particles"]["lattice"] = {6, 5, 1};
        }) == Approx(0.100).margin(1e-12));
  require_one_line_error(
      run_pdamp("validate " + edited_case("pdamp_lanes_bad.json", [](json& c) { c["damper"]["particles"]["lane_gap_m"] = "wide"; })),
      "/damper/particles/lane_gap_m: 'wide' is not allowed");
  require_one_line_error(run_pdamp("validate " + edited_case("pdamp_lot_bad.json", [](json& c) {
                           c["damper"]["particles"]["lot_diameter_variation_m"] = 0.01;
                         })),
                         "/damper/particles/lot_diameter_variation_m: = 0.01: must be a finite number >= 0 and <= 0.001");
}

TEST_CASE("the closed-form commands take the bed models' flags and refuse bad values in one line", "[cli]") {
  // e_b = 0.2, κ = 0.4: onset 0.273478 h, peak 0.297089 h, η*_pk 1.364 (docs/theory.md §3.1).
  const auto r = run_pdamp("optimum --model rolling --clearance 0.01 --bed-restitution 0.2 --json");
  REQUIRE(r.exit_code == 0);
  const json j = json::parse(r.out);
  CHECK(j["x_onset_m"].get<double>() == Approx(0.00273478).epsilon(1e-5));
  CHECK(j["x_opt_ideal_m"].get<double>() == Approx(0.00297089).epsilon(1e-5));
  require_one_line_error(run_pdamp("optimum --model rolling --clearance 0.01 --bed-restitution 1.2"),
                         "--bed-restitution: '1.2': must be a finite number >= 0 and <= 0.9");
  require_one_line_error(
      run_pdamp("loss --model rolling --clearance 0.01 --amplitude 0.003 --frequency 3 --below-onset map"),
      "--below-onset: 'map' is not allowed (one of: scattered_fit impact_map rolling_tail)");
  const auto held = run_pdamp("loss --model coulomb_block --clearance 0.003 --amplitude 0.001 --frequency 3.6 "
                              "--friction 0.2 --json");
  REQUIRE(held.exit_code == 0);
  const json h = json::parse(held.out);
  CHECK(h["regime"] == "stuck");
  CHECK(h["eta_star"] == 0.0);
}

// GNU-style "--flag=value" is the same as "--flag value" (the value is all after the first
// '='); a flag without a value refuses one. pdamp --version names what a bug report needs.
TEST_CASE("a flag written --flag=value is --flag value, and pdamp --version names the build", "[cli]") {
  const auto spaced = run_pdamp({"loss", "--model", "rolling", "--clearance", "0.01", "--amplitude", "0.004",
                                 "--frequency", "10", "--json"});
  const auto joined = run_pdamp({"loss", "--model=rolling", "--clearance=0.01", "--amplitude=0.004", "--frequency=10",
                                 "--json"});
  REQUIRE(spaced.exit_code == 0);
  CHECK(joined.exit_code == 0);
  CHECK(joined.out == spaced.out);
  require_one_line_error(run_pdamp({"loss", "--model=rolling", "--clearance=0.01", "--amplitude=0.004",
                                    "--frequency=10", "--json=1"}),
                         "--json: takes no value");
  require_one_line_error(run_pdamp({"loss", "--model=rolling", "--clearance=", "--amplitude=0.004", "--frequency=10"}),
                         "--clearance: '': must be a finite number");

  const auto version = run_pdamp(std::string("--version"));
  CHECK(version.exit_code == 0);
  CHECK_THAT(version.out, Catch::StartsWith("pdamp ") && Catch::Contains("\ncommit ") &&
                              Catch::Contains("DEM physics model version ") && Catch::Contains("\nbuild "));
  require_one_line_error(run_pdamp(std::string("--version extra")), "--version: takes no further arguments");
}

// A length typed in millimetres where the flag takes metres (`--clearance 100`: a 40 m design
// stroke) is answered, with a warning naming the flag and the metres it meant; a damper's
// real sizes get none.
TEST_CASE("a length flag above a metre warns that flags take metres", "[cli]") {
  const auto mm = run_pdamp(std::string("optimum --model rolling --clearance 100 --json"));
  REQUIRE(mm.exit_code == 0);
  const auto warnings = nlohmann::json::parse(mm.out)["warnings"];
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0].get<std::string>(), Catch::Contains("--clearance 100 is 100 m") &&
                                                 Catch::Contains("flags take metres (0.1 for 100 mm)"));
  CHECK_THAT(mm.err, Catch::Contains("pdamp: warning: --clearance 100"));
  const auto m = run_pdamp(std::string("loss --model rolling --clearance 0.01 --amplitude 0.004 --frequency 10 --json"));
  REQUIRE(m.exit_code == 0);
  CHECK(m.err.find("flags take metres") == std::string::npos);
  CHECK(run_pdamp(std::string("size --model rolling --stroke 5")).err.find("--stroke 5 is 5 m") != std::string::npos);
}
