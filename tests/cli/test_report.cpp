// The HTML report of pdamp run -o DIR (report/src/html_report.cpp): escaping of hostile
// case text, base64 against RFC 4648's vectors, embedded pictures, the no-gnuplot note,
// that only pdamp run writes it, and the answer each shipped case's page opens with
// (rendered by headless Chromium where it is installed).
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "cli/cli_support.hpp"
#include "pdamp/report/external_program.hpp"
#include "pdamp/report/html_report.hpp"
#include "pdamp/report/output_dir.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

const std::string kHostile = "<script>alert('x')</script><img src=x onerror=alert(1)>&\"";

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// Nothing in the page can run: every tag is one the report itself writes (no script, no
/// element a hostile text brought in), and every picture is a data: URI.
void require_inert(const std::string& html) {
  const std::string page = lower(html);
  CHECK(page.find("<script") == std::string::npos);
  CHECK(page.find("javascript:") == std::string::npos);
  static const std::vector<std::string> kOwnTags = {"!doctype", "html", "head", "meta", "title", "style", "body",
                                                    "h1", "h2", "h3", "p", "table", "tr", "th", "td", "figure",
                                                    "img", "figcaption", "ul", "li", "code", "section"};
  for (std::size_t at = page.find('<'); at != std::string::npos; at = page.find('<', at + 1)) {
    std::size_t end = at + 1;
    if (end < page.size() && page[end] == '/') ++end;
    std::size_t stop = end;
    while (stop < page.size() && (std::isalnum(static_cast<unsigned char>(page[stop])) || page[stop] == '!')) ++stop;
    const std::string tag = page.substr(end, stop - end);
    INFO("tag <" << tag << "> at " << at);
    CHECK(std::find(kOwnTags.begin(), kOwnTags.end(), tag) != kOwnTags.end());
    if (tag == "img") CHECK(page.compare(stop, 4, " alt") == 0);  // <img alt="..." src="data:...">
  }
  for (std::size_t at = page.find(" src=\""); at != std::string::npos; at = page.find(" src=\"", at + 1))
    CHECK(page.compare(at + 6, 5, "data:") == 0);
}

}  // namespace

TEST_CASE("html_escape turns the five markup characters into character references", "[cli][report]") {
  CHECK(pdamp::report::html_escape("a<b>&\"c'") == "a&lt;b&gt;&amp;&quot;c&#39;");
  CHECK(pdamp::report::html_escape("plain text, μ = 0.3") == "plain text, μ = 0.3");  // UTF-8 untouched
}

TEST_CASE("base64 gives RFC 4648's test vectors", "[cli][report]") {
  // RFC 4648 §10.
  CHECK(pdamp::report::base64("") == "");
  CHECK(pdamp::report::base64("f") == "Zg==");
  CHECK(pdamp::report::base64("fo") == "Zm8=");
  CHECK(pdamp::report::base64("foo") == "Zm9v");
  CHECK(pdamp::report::base64("foob") == "Zm9vYg==");
  CHECK(pdamp::report::base64("fooba") == "Zm9vYmE=");
  CHECK(pdamp::report::base64("foobar") == "Zm9vYmFy");
  CHECK(pdamp::report::base64(std::string("\xff\x00\x80", 3)) == "/wCA");  // high bytes and a NUL
}

TEST_CASE("the report escapes hostile case text and embeds pictures as data URIs", "[cli][report]") {
  pdamp::report::ReportInput in;
  in.case_name = kHostile;
  in.case_description = "description " + kHostile;
  in.case_file = "/cases/" + kHostile + ".json";
  in.result = {{"task", "decay"}, {"case", kHostile}, {"settling_time_s", 17.31}, {"decay", {{"outcome", kHostile}}}};
  in.warnings = {"warning " + kHostile};
  in.pictures = {{"decay.png", "\x89PNG\r\n\x1a\n"}};
  const std::string html = pdamp::report::report_html(in);
  require_inert(html);
  CHECK(html.find("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;") != std::string::npos);
  CHECK(html.find("Content-Security-Policy") != std::string::npos);
  CHECK(html.find("17.3") != std::string::npos);  // the key number, to three significant digits
  // The PNG signature 89 50 4E 47 0D 0A 1A 0A is "iVBORw0KGgo=" in base64.
  CHECK(html.find("src=\"data:image/png;base64,iVBORw0KGgo=\"") != std::string::npos);
  CHECK(html.find("gnuplot was not found") == std::string::npos);

  in.pictures.clear();
  in.gnuplot_found = false;
  CHECK(pdamp::report::report_html(in).find("gnuplot was not found") != std::string::npos);

  // Results that lack what an answer reads (a task cut short, nothing settled, no
  // verification) still give a page: the missing numbers print as "–".
  pdamp::tasks::FillingRatiosResult design;
  design.optimum.chosen.layers.resize(1);
  design.optimum.chosen.settling_time_s = NAN;
  design.verification.emplace();
  pdamp::tasks::FrfResult frf;
  frf.harmonic.emplace();
  frf.harmonic->response.peaks.resize(1);
  frf.harmonic->response.peaks[0].frequency_hz = NAN;
  frf.harmonic->response.linear_peaks.resize(1);
  pdamp::tasks::DamperDesignResult damper;
  damper.operating_point.emplace();
  damper.operating_point->loss.stroke_over_onset = 0.5;
  pdamp::tasks::ModesResult modes;
  modes.mode_count = 1;
  modes.frequencies_with_containers_hz = Eigen::VectorXd::Constant(1, NAN);
  modes.modal.natural_frequencies_hz = Eigen::VectorXd::Constant(1, NAN);
  const pdamp::tasks::PlacementStudy placement;
  const pdamp::tasks::DecayResult decay = [] {
    pdamp::tasks::DecayResult d;
    d.decay.samples.resize(1);
    return d;
  }();
  const pdamp::report::TaskResult partial[] = {&design, &frf, &damper, &modes, &placement, &decay};
  in.result = json::object();
  for (const auto& typed : partial) {
    in.typed = typed;
    INFO(typed.index());
    std::string page;
    CHECK_NOTHROW(page = pdamp::report::report_html(in));
    CHECK(page.find("<h2>Answer</h2>") != std::string::npos);
    CHECK_FALSE(std::regex_search(page, std::regex("\\b-?nan\\b")));  // a number not known prints as "–"
  }
}

TEST_CASE("a filling-ratio answer names the models its prediction came from", "[cli][report]") {
  pdamp::report::ReportInput in;
  in.case_name = "link";
  in.result = json::object();
  pdamp::tasks::FillingRatiosResult design;
  design.optimum.chosen.layers.resize(1);
  in.typed = &design;
  CHECK_THAT(pdamp::report::report_html(in), Catch::Contains("The prediction comes from the closed forms") &&
                                                 Catch::Contains("--method calibrated"));
  design.calibration.emplace();
  design.calibration->beds.resize(7);
  design.calibration->runs = 2;
  CHECK_THAT(pdamp::report::report_html(in),
             Catch::Contains("The prediction comes from beds calibrated by the DEM (7 beds, 2 run now") &&
                 !Catch::Contains("The prediction comes from the closed forms"));
}

TEST_CASE("a placement answer names the models its damping ratios came from and that the DEM did not check them",
          "[cli][report]") {
  pdamp::report::ReportInput in;
  in.case_name = "beam";
  in.result = json::object();
  pdamp::tasks::PlacementStudy placement;
  in.typed = &placement;
  CHECK_THAT(pdamp::report::report_html(in),
             Catch::Contains("come from the closed forms") && Catch::Contains("Not checked by the DEM"));
  placement.method = pdamp::case_file::LossMethod::kField;
  CHECK_THAT(pdamp::report::report_html(in), Catch::Contains("come from each layer&#39;s effective field"));  // escaped
}

// The verdicts of the placement's and the clearance's DEM checks, from typed results built here.
TEST_CASE("a placement or clearance answer gives the DEM check's verdict and why it failed", "[cli][report]") {
  pdamp::report::ReportInput in;
  in.case_name = "beam";
  in.result = json::object();
  pdamp::tasks::PlacementStudy placement;
  placement.verification.emplace();
  auto& v = *placement.verification;
  v.settings.tolerance_relative = 0.15;
  v.sites.resize(2);
  v.sites[0].predicted_objective = 0.0153, v.sites[0].dem_objective = 0.00128;
  v.sites[1].predicted.position_m = 1.71, v.sites[1].predicted_objective = 0.0016, v.sites[1].dem_objective = 0.00045;
  v.ranking_agrees = true;
  in.typed = &placement;
  CHECK_THAT(pdamp::report::report_html(in),
             Catch::Contains("DEM check: FAIL") && Catch::Contains("Do not build on the prediction") &&
                 Catch::Contains("the DEM still ranks the chosen site first"));

  pdamp::tasks::ClearanceStudy clearance;
  clearance.verification.emplace();
  auto& c = *clearance.verification;
  c.settings.tolerance_relative = 0.15;
  c.checks.resize(2);
  c.checks[1].ranking = pdamp::tasks::DemRanking::kIndistinguishable;
  c.chosen_agrees = c.ranking_agrees = c.passed = true;
  in.typed = &clearance;
  CHECK_THAT(pdamp::report::report_html(in),
             Catch::Contains("DEM check: PASS") && Catch::Contains("indistinguishable") &&
                 Catch::Contains("the ranking there is the prediction&#39;s alone"));
}

TEST_CASE("pdamp run -o DIR writes report.html with the case's plots, and other commands write none", "[cli][report]") {
  const TempDir dir("report_run");
  const std::string path = (dir.path / "hostile.json").string();
  {
    std::ifstream in(case_path("low_intensity_36_spheres.json"));
    json c = json::parse(in);
    c["name"] = kHostile;
    c["description"] = kHostile;
    std::ofstream(path) << c.dump(2);
  }
  const fs::path out = dir.path / "out";
  const auto r = run_pdamp({"run", path, "-o", out.string(), "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  REQUIRE(fs::is_regular_file(out / "report.html"));
  const std::string html = slurp(out / "report.html");
  require_inert(html);
  CHECK(html.find("&lt;script&gt;") != std::string::npos);
  // The answer: the 36-sphere bed's clearance h_roll = 0.1 m (docs/cases.md) and the
  // rolling design stroke 0.4 h = 0.04 m (docs/theory.md §3), in mm.
  CHECK(html.find("with a clearance of 100 mm along the drive") != std::string::npos);
  CHECK(html.find("with a stroke of 40 mm") != std::string::npos);
  if (fs::is_regular_file(out / "eta_curve.png")) {
    CHECK(html.find("data:image/png;base64,iVBORw0KGgo") != std::string::npos);  // the PNG, embedded
    CHECK(html.find("eta_curve.png") != std::string::npos);
  } else {
    CHECK(html.find("gnuplot was not found") != std::string::npos);
  }
  // report.html is part of the run's set of outputs (the manifest), so the next run replaces it.
  const json listed = json::parse(slurp(out / ".pdamp-outputs.json"));
  CHECK(std::find(listed["files"].begin(), listed["files"].end(), "report.html") != listed["files"].end());
  const json result = json::parse(r.out);
  CHECK(std::any_of(result["outputs"].begin(), result["outputs"].end(),
                    [](const json& p) { return p.get<std::string>().find("report.html") != std::string::npos; }));

  // A structure task: the decay's settling time is in the key numbers, its plot embedded.
  const fs::path decay_out = dir.path / "decay";
  const std::string decay_case = std::string(PDAMP_SOURCE_DIR) + "/tests/cli/data/cantilever_decay.json";
  REQUIRE(run_pdamp({"run", decay_case, "-o", decay_out.string()}).exit_code == 0);
  const std::string decay_html = slurp(decay_out / "report.html");
  CHECK(decay_html.find("settling_time_s") != std::string::npos);
  if (fs::is_regular_file(decay_out / "decay.png")) CHECK(decay_html.find("decay.png") != std::string::npos);

  // pdamp decay (not run) into a fresh folder: no report.
  const fs::path plain = dir.path / "plain";
  REQUIRE(run_pdamp({"decay", decay_case, "-o", plain.string()}).exit_code == 0);
  CHECK_FALSE(fs::exists(plain / "report.html"));
}

// Reference: gnuplot exits 0 with a picture cut short when the disk fills (an SVG without its
// closing tag, a PNG without its IEND chunk): such a staged set must not replace a good one.
// A script that writes a cut SVG stands for it.
TEST_CASE("a picture gnuplot leaves incomplete ends the run before the earlier results are replaced", "[cli][report]") {
  if (!pdamp::report::find_executable("gnuplot")) return;  // nothing to run
  const TempDir dir("incomplete_picture");
  std::ofstream(dir.path / "kept.csv") << "1,2\n";
  {
    pdamp::report::OutputDir out(dir.path);
    out.add("kept.csv", "1,2\n");
    out.commit();
  }
  pdamp::report::OutputDir out(dir.path);
  out.add("kept.csv", "3,4\n");
  CHECK_THROWS_WITH(out.add_plot("cut.gp", "set print 'cut.svg'\nprint '<svg><g>'\nunset print\n", {"cut.svg"}),
                    Catch::Contains("cut.svg: gnuplot wrote it incomplete"));
  std::ifstream kept(dir.path / "kept.csv");
  std::string line;
  std::getline(kept, line);
  CHECK(line == "1,2");  // the earlier set is untouched
  CHECK_FALSE(fs::exists(dir.path / "cut.svg"));
}

namespace {

/// The text of the page's answer section, tags removed and the five references undone.
std::string answer_text(const std::string& html) {
  const auto begin = html.find("<section class=\"answer\">");
  const auto end = html.find("</section>");
  REQUIRE(begin != std::string::npos);
  REQUIRE(end != std::string::npos);
  std::string text = std::regex_replace(html.substr(begin, end - begin), std::regex("<[^>]*>"), " ");
  for (const auto& [ref, ch] : std::vector<std::pair<std::string, std::string>>{
           {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&#39;", "'"}, {"&amp;", "&"}})
    for (std::size_t at; (at = text.find(ref)) != std::string::npos;) text.replace(at, ref.size(), ch);
  return text;
}

/// `value` as the page should print it: three significant digits (C's %.3g, trailing zeros dropped).
std::string three(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

}  // namespace

TEST_CASE("the report of each shipped case opens with its answer in g, mm and s, three digits each", "[cli][report]") {
  const TempDir dir("report_answers");
  for (const char* name : {"low_intensity_36_spheres", "high_intensity_cylinder", "buffered_wall_60hz", "manipulator_link_decay",
                           "beam_base_excited", "free_free_beam_shaker", "free_free_beam_placement"}) {
    INFO(name);
    const fs::path out = dir.path / name;
    const auto r = run_pdamp({"run", case_path(std::string(name) + ".json"), "-o", out.string(), "--json"});
    REQUIRE(r.exit_code == 0);
    const json result = json::parse(r.out);
    const std::string html = slurp(out / "report.html");
    require_inert(html);
    const std::string answer = answer_text(html);
    INFO(answer);
    // The answer comes first, then the evidence, then the details.
    CHECK(html.find("<h2>Answer</h2>") < html.find("<h2>Evidence</h2>"));
    CHECK(html.find("<h2>Evidence</h2>") < html.find("<h2>Details</h2>"));
    // No decimal number in the answer carries more than three significant digits (counts are whole).
    const std::regex decimal(R"((\d+)\.(\d+))");
    for (auto it = std::sregex_iterator(answer.begin(), answer.end(), decimal); it != std::sregex_iterator(); ++it) {
      std::string digits = (*it)[1].str() + (*it)[2].str();
      digits.erase(0, digits.find_first_not_of('0'));
      CHECK(digits.size() <= 3);
    }
    require_plain_csv_tables(out);
    const std::string task = result["task"];
    if (std::string(name) == "low_intensity_36_spheres") {
      CHECK_THAT(answer, Catch::Contains("A bed of 36 steel spheres of 5 mm radius"));
      CHECK_THAT(answer, Catch::Contains("η* = " + three(result["operating_point"]["eta_star"].get<double>())));
      CHECK_THAT(answer, Catch::Contains("times the onset of collect-and-collide"));
    }
    if (std::string(name) == "buffered_wall_60hz")
      CHECK_THAT(answer, Catch::Contains(three(result["buffer"]["layer_thickness_m"].get<double>() * 1e3) + " mm thick"));
    if (task == "decay") {
      // The link settles with particles and not within the 30 s without them (its structural
      // damping alone, ζ = 0.003 at about 3.5 Hz, takes about 60 s to 5 %).
      CHECK_THAT(answer, Catch::Contains("settles in " + three(result["settling_time_s"].get<double>()) + " s"));
      CHECK(result["decay"]["without_beds"]["settling_time_s"].is_null());
      CHECK_THAT(answer, Catch::Contains("without particles (empty containers) it does not settle within 30 s"));
    }
    if (task == "frf") {
      // Each peak against the peak without particles nearest in frequency (the same mode).
      const json& peak = result["frf"]["peaks"][0];
      const json* bare = nullptr;
      for (const auto& lin : result["frf"]["linear_peaks"])
        if (!bare || std::abs(lin["frequency_hz"].get<double>() - peak["frequency_hz"].get<double>()) <
                         std::abs((*bare)["frequency_hz"].get<double>() - peak["frequency_hz"].get<double>()))
          bare = &lin;
      REQUIRE(bare);
      CHECK_THAT(answer, Catch::Contains("the particles lower the peak " +
                                         three((*bare)["magnitude"].get<double>() / peak["magnitude"].get<double>()) + " times"));
    }
    if (task == "placement") CHECK_THAT(answer, Catch::Contains("Put the damper " + three(result["design"]["position_m"].get<double>()) + " m along"));
  }

  // Headless Chromium reads the page as a browser does: the answer is in its document,
  // and its screenshot is a whole PNG (CI installs chromium; elsewhere this part is skipped).
  const auto chromium = pdamp::report::find_executable("chromium");
  if (!chromium) {
    WARN("chromium is not installed: the page is not rendered");
    return;
  }
  const fs::path page = dir.path / "manipulator_link_decay" / "report.html";
  // --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start.
  const std::vector<std::string> common = {"--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                                           "--window-size=1100,1800"};
  auto dump = common;
  dump.insert(dump.end(), {"--dump-dom", "file://" + page.string()});
  REQUIRE(pdamp::report::run_program(*chromium, dump, dir.path, dir.path / "dom.html") == 0);
  const std::string dom = slurp(dir.path / "dom.html");
  CHECK_THAT(dom, Catch::Contains("<h2>Answer</h2>"));
  CHECK_THAT(dom, Catch::Contains("without particles (empty containers) it does not settle within 30 s"));
  auto shot = common;
  shot.insert(shot.end(), {"--screenshot=" + (dir.path / "report.png").string(), "file://" + page.string()});
  REQUIRE(pdamp::report::run_program(*chromium, shot, dir.path, dir.path / "chromium.log") == 0);
  const std::string png = slurp(dir.path / "report.png");
  CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  CHECK(png.find("IEND") != std::string::npos);  // the last chunk: the picture is whole
}
