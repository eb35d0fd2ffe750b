// DIR/report.html of pdamp run: a page built from the typed result (the answer and its
// evidence), the result JSON (every number) and the staged pictures.
// The CLI only formats here: numbers come from the result, pictures from gnuplot.
#include "pdamp/report/html_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>

#include "pdamp/base/output_file.hpp"
#include "report_answer.hpp"

namespace pdamp::report {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

/// Rows of the generic key-number table at most (a result is a few dozen numbers; the
/// long series belong in the CSV files).
constexpr std::size_t kMaxGenericRows = 120;
/// Rows of one JSON array shown as a table at most.
constexpr std::size_t kMaxArrayRows = 40;

/// Keys that are paths, prose or bulky series, not key numbers.
bool skipped_key(const std::string& key) {
  static const char* const kSkipped[] = {"file", "plot", "outputs", "warnings", "report", "message", "envelope",
                                         "envelope_points", "energy", "what", "rule", "designs", "verification",
                                         "solver", "rounding", "calibration", "design_loop"};
  return std::any_of(std::begin(kSkipped), std::end(kSkipped), [&](const char* s) { return key == s; });
}

std::string scalar_text(const json& v) {
  if (v.is_null()) return "–";
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer() || v.is_number_unsigned()) return std::to_string(v.get<long long>());
  if (v.is_number()) return three_digits(v.get<double>());
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

bool is_scalar(const json& v) { return !v.is_object() && !v.is_array(); }

bool ends_with(const std::string& text, std::string_view end) {
  return text.size() > end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

/// A short array of numbers ([x, y], per-layer slabs) reads as one value.
bool is_short_number_list(const json& v) {
  return v.is_array() && v.size() <= 8 && std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); });
}

std::string list_text(const json& v) {
  std::string out;
  for (const auto& x : v) out += (out.empty() ? "" : ", ") + scalar_text(x);
  return out;
}

/// The key numbers: top-level scalars and those one object down ("decay / settling_time_s").
void flatten(const json& object, const std::string& prefix, int depth, std::vector<std::pair<std::string, std::string>>& rows) {
  for (const auto& [key, value] : object.items()) {
    if (rows.size() >= kMaxGenericRows || skipped_key(key)) continue;
    const std::string name = prefix.empty() ? key : prefix + " / " + key;
    if (value.is_number() && ends_with(key, "_m"))
      rows.push_back({name.substr(0, name.size() - 2) + " (mm)", in_mm(value.get<double>())});
    else if (value.is_number() && ends_with(key, "_kg"))
      rows.push_back({name.substr(0, name.size() - 3) + " (g)", in_g(value.get<double>())});
    else if (is_scalar(value)) rows.push_back({name, scalar_text(value)});
    else if (is_short_number_list(value)) rows.push_back({name, list_text(value)});
    else if (value.is_object() && depth < 1) flatten(value, name, depth + 1, rows);
  }
}

std::string table(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows) {
  std::ostringstream out;
  out << "<table>\n<tr>";
  for (const auto& h : head) out << "<th>" << html_escape(h) << "</th>";
  out << "</tr>\n";
  for (const auto& row : rows) {
    out << "<tr>";
    for (const auto& cell : row) out << "<td>" << html_escape(cell) << "</td>";
    out << "</tr>\n";
  }
  out << "</table>\n";
  return out.str();
}

/// Arrays of flat objects (peaks, modes) as tables: one column per scalar key.
std::string array_tables(const json& result) {
  std::ostringstream out;
  std::vector<std::pair<std::string, const json*>> arrays;
  for (const auto& [key, value] : result.items()) {
    if (skipped_key(key)) continue;
    if (value.is_array()) arrays.push_back({key, &value});
    if (value.is_object())
      for (const auto& [inner, v] : value.items())
        if (v.is_array() && !skipped_key(inner)) arrays.push_back({key + " / " + inner, &v});
  }
  for (const auto& [name, array] : arrays) {
    if (array->empty() || !std::all_of(array->begin(), array->end(), [](const json& e) { return e.is_object(); })) continue;
    std::vector<std::string> columns;
    for (const auto& e : *array)
      for (const auto& [k, v] : e.items())
        if (is_scalar(v) && std::find(columns.begin(), columns.end(), k) == columns.end()) columns.push_back(k);
    if (columns.empty()) continue;
    std::vector<std::vector<std::string>> rows;
    for (std::size_t i = 0; i < array->size() && i < kMaxArrayRows; ++i) {
      std::vector<std::string> row;
      for (const auto& col : columns) row.push_back((*array)[i].contains(col) ? scalar_text((*array)[i][col]) : "");
      rows.push_back(row);
    }
    out << "<h3>" << html_escape(name) << "</h3>\n" << table(columns, rows);
    if (array->size() > kMaxArrayRows)
      out << "<p class=\"note\">" << array->size() - kMaxArrayRows << " more rows in the result JSON.</p>\n";
  }
  return out.str();
}

std::string mm(double v) { return three_digits(v * 1e3); }
std::string seconds(double v) { return std::isfinite(v) ? three_digits(v) : "not settled"; }
std::string slab_list(const std::vector<double>& slabs) {
  std::string out;
  for (const double n : slabs) out += (out.empty() ? "" : ", ") + three_digits(n);
  return out;
}
std::string difference_text(double relative, const std::string& prefix = "") {
  return std::isfinite(relative) ? prefix + format_number(100.0 * relative, 3) + " %" : "only one settled";
}

/// filling_ratios: the designs side by side.
std::string designs_section(const tasks::FillingRatiosResult& result) {
  const auto& r = result.optimum;
  const std::pair<const char*, const optimizer::FillingDesign*> designs[] = {
      {"chosen", &r.chosen}, {"baseline", &r.baseline}, {"bare", &r.bare},
      {"same_mass", &r.same_mass}, {"initial", &r.initial}, {"relaxed", &r.relaxed}};
  std::vector<std::vector<std::string>> rows;
  for (const auto& [name, d] : designs) {
    std::string clearances;
    for (const auto& l : d->layers) clearances += (clearances.empty() ? "" : ", ") + mm(l.clearance_m);
    rows.push_back({name, slab_list(d->slabs()), clearances, in_g(d->total_mass_kg), seconds(d->settling_time_s),
                    three_digits(d->objective)});
  }
  std::string layers;
  for (const auto& l : r.chosen.layers) layers += (layers.empty() ? "" : ", ") + l.name;
  return "<h3>Designs</h3>\n<p>Layers: " + html_escape(layers) + " (whole slabs n, clearance h = L − n·2r).</p>\n" +
         table({"design", "slabs n", "clearance h / mm", "particle mass", "settling time / s", "objective"}, rows);
}

/// The optimiser's numbers (the result JSON's solver block) and the rounding rule.
std::string solver_section(const json& result) {
  if (!result.contains("solver") || !result["solver"].is_object()) return "";
  std::vector<std::pair<std::string, std::string>> rows;
  flatten(result["solver"], "", 1, rows);
  if (result["solver"].contains("report")) rows.push_back({"report", scalar_text(result["solver"]["report"])});
  if (result.contains("rounding") && result["rounding"].contains("rule"))
    rows.push_back({"rounding", scalar_text(result["rounding"]["rule"])});
  std::vector<std::vector<std::string>> cells;
  for (const auto& [k, v] : rows) cells.push_back({k, v});
  return "<h3>Optimiser</h3>\n" + table({"", ""}, cells);
}

std::string verification_section(const tasks::Verification& v) {
  const bool settling = v.settling_objective;
  const auto objective = [&](double settling_time_s, double value) {
    return settling ? seconds(settling_time_s) : three_digits(value);
  };
  std::vector<std::vector<std::string>> rows;
  for (const auto& d : v.designs) {
    rows.push_back({d.name, objective(d.predicted.settling_time_s, d.predicted_objective),
                    objective(d.dem.settling.settling_time_s, d.dem.objective), mm(d.predicted_end_envelope_m),
                    mm(d.dem.end_envelope_m), three_digits(d.dem.energy_error), difference_text(d.agreement.relative_difference),
                    d.passed ? "pass" : "FAIL"});
    if (const auto& s = d.softening_check)
      rows.push_back({d.name + ", check at softening " + three_digits(s->stiffness_softening), "",
                      objective(s->dem.settling.settling_time_s, s->dem.objective), "", mm(s->dem.end_envelope_m),
                      three_digits(s->dem.energy_error), difference_text(s->agreement.relative_difference, "judged run "),
                      s->agreement.within ? "converged" : "NOT CONVERGED"});
  }
  const std::string unit = settling ? "settling time / s" : "½∫e² dt / m² s";
  std::ostringstream out;
  out << "<h3>DEM verification</h3>\n<p>" << html_escape(tasks::Verification::kWhat)
      << ". Simulated " << three_digits(v.spec.duration_s) << " s each, stiffness softening "
      << three_digits(v.dem_stiffness_softening * v.spec.stiffness_softening) << ", tolerance "
      << format_number(100.0 * v.spec.tolerance_relative, 3) << " %.</p>\n"
      << table({"design", "predicted " + unit, "DEM " + unit, "predicted envelope at end / mm", "DEM envelope at end / mm",
                "DEM energy error", "DEM − predicted", "result"},
               rows);
  out << "<p>Ranking (chosen design ahead of the best single layer): predicted "
      << (v.predicted_chosen_ahead ? "yes" : "no") << ", DEM " << (v.dem_chosen_ahead ? "yes" : "no") << ": "
      << (v.ranking_passed ? "pass" : "FAIL") << ".</p>\n<p class=\"verdict " << (v.passed ? "pass" : "fail")
      << "\">Verification: " << (v.passed ? "PASS" : "FAIL") << "</p>\n";
  return out.str();
}

/// filling_ratios on calibrated beds: the beds, and the rounds of the design loop.
std::string calibration_section(const tasks::FillingRatiosResult& result) {
  std::ostringstream out;
  if (const auto& c = result.calibration) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& b : c->beds)
      rows.push_back({html_escape(b.layer), std::to_string(b.slabs), three_digits(b.extra_damping_ratio),
                      std::to_string(b.periods.size()), mm(b.stroke_min_m()) + " – " + mm(b.stroke_max_m()),
                      b.cached ? "cache" : "run now (" + seconds(b.wall_time_s) + " s)"});
    out << "<h3>Calibrated beds</h3>\n<p>"
        << html_escape(tasks::BedCalibration::kWhat) << ": "
        << three_digits(c->spec.duration_s) << " s each, stiffness softening " << three_digits(c->spec.stiffness_softening)
        << "; " << c->runs << " DEM decays run now, the others from " << html_escape(c->cache_dir.string()) << ".</p>\n"
        << table({"layer", "slabs", "extra damping ratio", "periods", "strokes / mm", "source"}, rows);
  }
  if (result.loop_outcome) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& r : result.rounds)
      for (const auto& d : r.designs)
        rows.push_back({std::to_string(r.round), d.name, slab_list(d.slabs), seconds(d.predicted_objective),
                        seconds(d.dem_objective), difference_text(d.relative_difference), d.passed ? "pass" : "FAIL",
                        d.name == "chosen" ? std::to_string(r.recalibrated.size()) : ""});
    out << "<h3>Design loop</h3>\n<p>Outcome: " << tasks::to_string(*result.loop_outcome) << ".</p>\n"
        << table({"round", "design", "slabs", "predicted", "DEM", "DEM − predicted", "result", "beds recalibrated after"},
                 rows);
  }
  return out.str();
}

/// What a picture shows, by its file name.
std::string caption(const std::string& file_name) {
  static const std::map<std::string, std::string> kCaptions = {
      {"eta_curve", "η*(X) of the closed forms: the onset (the cliff to the scattered state), the ideal peak and the design stroke"},
      {"backbone", "backbones: natural frequency and added damping against the damper's amplitude"},
      {"frf", "frequency response with the dampers and without the beds: magnitude over phase"},
      {"frf_dem", "frequency response, DEM in the loop"},
      {"frf_compare", "frequency response: closed forms, field and DEM"},
      {"decay", "free decay with the dampers, and without particles (dashed: the containers empty)"},
      {"decay_dem", "free decay, DEM in the loop, and without particles (dashed: the containers empty)"},
      {"decay_compare", "free-decay envelopes: chosen design, best single layer, case start and without particles (the containers empty)"},
      {"verify_decay", "DEM verification: envelopes by the DEM (solid) and as predicted (dashed: the closed forms or the calibrated beds)"},
      {"force_velocity", "DEM: container force and velocity"},
      {"field_map", "effective field"},
      {"field_cuts", "effective field: cuts with the closed form"}};
  const std::string stem = fs::path(file_name).stem().string();
  const auto it = kCaptions.find(stem);
  return it == kCaptions.end() ? stem : it->second;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The pictures staged in `folder`: each plot's PNG, or its SVG where there is no PNG.
std::vector<ReportPicture> staged_pictures(const fs::path& folder) {
  std::map<std::string, fs::path> png, svg;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    if (!entry.is_regular_file()) continue;
    const auto ext = entry.path().extension().string();
    if (ext == ".png") png[entry.path().stem().string()] = entry.path();
    if (ext == ".svg") svg[entry.path().stem().string()] = entry.path();
  }
  for (const auto& [stem, path] : png) svg.erase(stem);
  std::vector<ReportPicture> out;
  for (const auto* set : {&png, &svg})
    for (const auto& [stem, path] : *set) out.push_back({path.filename().string(), read_bytes(path)});
  return out;
}

}  // namespace

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += ch;
    }
  }
  return out;
}

std::string base64(std::string_view bytes) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string report_html(const ReportInput& in) {
  const json& r = in.result;
  const std::string task = r.is_object() && r.contains("task") ? scalar_text(r["task"]) : "";
  const auto* design = std::get_if<const tasks::FillingRatiosResult*>(&in.typed);
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      // No script and no fetch may run, whatever a text contains: pictures are data: URIs.
      << "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; style-src 'unsafe-inline'\">\n"
      << "<title>pdamp report: " << html_escape(in.case_name) << "</title>\n"
      << "<style>body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222}"
         "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:2px 8px;text-align:left;"
         "vertical-align:top}th{background:#eee}img{max-width:100%;border:1px solid #ddd}"
         ".note{color:#555}.verdict{font-weight:bold}.pass{color:#060}.fail{color:#b00}"
         ".answer{background:#f4f7fb;border-left:4px solid #36c;padding:0.3em 1em;font-size:1.05em}"
         "li.warning{color:#840}</style>\n</head>\n<body>\n";
  out << "<h1>" << html_escape(in.case_name) << "</h1>\n";
  out << "<p class=\"note\">Task " << html_escape(task) << ", case file " << html_escape(in.case_file)
      << ". Lengths in mm, masses in g, times in s; three significant digits (every digit in the result JSON).</p>\n";

  // 1. The answer: the design and what it gains, then the verdict of the check behind it.
  static const case_file::Case kNoCase;
  const Answer answer = report_answer(in.typed, in.case_read ? *in.case_read : kNoCase);
  out << "<section class=\"answer\">\n<h2>Answer</h2>\n";
  if (answer.paragraphs.empty()) out << "<p>The result's numbers are under Details below.</p>\n";
  for (const auto& paragraph : answer.paragraphs) out << "<p>" << html_escape(paragraph) << "</p>\n";
  if (!answer.verdict.empty())
    out << "<p class=\"verdict" << (answer.passed ? (*answer.passed ? " pass" : " fail") : "") << "\">"
        << html_escape(answer.verdict) << "</p>\n";
  if (!in.warnings.empty())
    out << "<p class=\"note\">" << in.warnings.size() << (in.warnings.size() == 1 ? " warning" : " warnings")
        << " below: each says where a model leaves its range.</p>\n";
  out << "</section>\n";

  // 2. The evidence: plots, the DEM's check, the beds it rests on, the warnings.
  out << "<h2>Evidence</h2>\n";
  if (!in.gnuplot_found)
    out << "<p class=\"note\">gnuplot was not found: this report has no plots. The data (CSV) and the gnuplot scripts "
           "(.gp) are in the output folder; run <code>gnuplot NAME.gp</code> there once gnuplot is installed.</p>\n";
  else if (in.pictures.empty())
    out << "<p class=\"note\">This task wrote no plots.</p>\n";
  for (const auto& p : in.pictures) {
    const bool svg = fs::path(p.file_name).extension() == ".svg";
    out << "<figure>\n<img alt=\"" << html_escape(p.file_name) << "\" src=\"data:" << (svg ? "image/svg+xml" : "image/png")
        << ";base64," << base64(p.bytes) << "\">\n<figcaption>" << html_escape(caption(p.file_name)) << " ("
        << html_escape(p.file_name) << ")</figcaption>\n</figure>\n";
  }
  if (design && (*design)->verification) out << verification_section(*(*design)->verification);
  if (design) out << calibration_section(**design);
  out << "<h3>Warnings</h3>\n";
  if (in.warnings.empty()) out << "<p>None.</p>\n";
  else {
    out << "<ul>\n";
    for (const auto& w : in.warnings) out << "<li class=\"warning\">" << html_escape(w) << "</li>\n";
    out << "</ul>\n";
  }

  // 3. The details: the case, the solver, every number, provenance.
  out << "<h2>Details</h2>\n";
  if (!in.case_description.empty()) out << "<p>" << html_escape(in.case_description) << "</p>\n";
  std::vector<std::pair<std::string, std::string>> rows;
  if (r.is_object()) flatten(r, "", 0, rows);
  std::vector<std::vector<std::string>> cells;
  for (const auto& [k, v] : rows) cells.push_back({k, v});
  if (design) out << designs_section(**design);
  if (r.is_object()) out << solver_section(r);
  out << "<h3>Numbers</h3>\n" << table({"quantity", "value"}, cells);
  if (r.is_object()) out << array_tables(r);
  out << "<h3>Provenance</h3>\n<p class=\"note\">" << html_escape(in.provenance.empty() ? "pdamp" : in.provenance)
      << "; case file " << html_escape(in.case_file) << "; written by pdamp run.</p>\n";
  out << "</body>\n</html>\n";
  return out.str();
}

void stage_report(OutputDir& files, const case_file::Case& c, const TaskResult& typed, const json& result,
                  const std::vector<std::string>& warnings, const std::string& provenance) {
  const fs::path page = files.staged_path("report.html");
  ReportInput in;
  in.case_name = c.name;
  in.case_description = c.description;
  in.case_file = c.path;
  in.case_read = &c;
  in.provenance = provenance;
  in.typed = typed;
  in.result = result;
  in.warnings = warnings;
  in.pictures = staged_pictures(page.parent_path());
  in.gnuplot_found = gnuplot_available();
  base::write_file_synced(page, report_html(in), files.dir() / "report.html");
}

}  // namespace pdamp::report
