// Job arrays for the effective-field sweep: `pdamp field --shard I/N` and
// `pdamp field merge` through the built binary (formulas source: milliseconds per run).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

/// The shipped low-intensity case on an 18-node grid (3 frequencies x 6 strokes), with `edit`,
/// written to the temp folder as `name`: one name per test case, as ctest -j2 runs them at once.
std::string shard_case(const std::string& name, const std::function<void(json&)>& edit = {}) {
  return edited_case(name, [&](json& c) {
    c["field"] = {{"axis0", {{"min", 1.5}, {"max", 2.5}, {"count", 3}}},
                  {"axis1", {{"min", 0.01}, {"max", 0.08}, {"count", 6}, {"spacing", "log"}}}};
    if (edit) edit(c);
  });
}

/// "I/N" and "s<i>", built with += (GCC 12 warns falsely, -Wrestrict, on "s" + to_string(i)).
std::string shard_arg(int i, int n) {
  std::string text = std::to_string(i);
  text += '/';
  text += std::to_string(n);
  return text;
}

std::string shard_folder(int i) {
  std::string name = "s";
  name += std::to_string(i);
  return name;
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  return json::parse(in);
}

/// field.json without its creation time (the only thing two runs may differ in).
json field_values(const fs::path& dir) {
  json field = read_json(dir / "field.json");
  field["provenance"].erase("created_utc");
  return field;
}

/// Runs shard i of n of `case_file` into dir/s<i>; returns the folder.
fs::path run_shard(const std::string& case_file, const fs::path& dir, int i, int n) {
  const fs::path out = dir / shard_folder(i);
  const auto r = run_pdamp({"field", case_file, "--source", "formulas", "--shard", shard_arg(i, n),
                            "-o", out.string(), "--json"});
  REQUIRE(r.exit_code == 0);
  return out;
}

}  // namespace

TEST_CASE("pdamp field --shard writes only its log, and merge equals the serial field bit for bit", "[cli]") {
  TempDir tmp("field_shards_merge");
  const std::string c = shard_case("pdamp_shards_merge.json");
  REQUIRE(run_pdamp({"field", c, "--source", "formulas", "-o", (tmp.path / "serial").string()}).exit_code == 0);

  std::vector<std::string> shards;
  std::size_t points = 0;
  for (int i = 0; i < 3; ++i) {
    const fs::path out = tmp.path / shard_folder(i);
    const auto r = run_pdamp({"field", c, "--source", "formulas", "--shard", shard_arg(i, 3), "-o",
                              out.string(), "--json"});
    REQUIRE(r.exit_code == 0);
    const json o = json::parse(r.out);
    CHECK(o["shard"] == shard_arg(i, 3));
    CHECK(o["points"] == 6);
    CHECK(o["points_in_grid"] == 18);
    points += o["points"].get<std::size_t>();
    CHECK(fs::exists(out / "field_sweep.jsonl"));
    CHECK(fs::exists(out / "shard.json"));
    CHECK(!fs::exists(out / "field.json"));  // a shard has no field of its own
    shards.push_back(out.string());
  }
  CHECK(points == 18);
  // Folders or the logs themselves, in any order.
  const auto r = run_pdamp({"field", "merge", c, "--source", "formulas", shards[2], shards[0] + "/field_sweep.jsonl",
                            shards[1], "-o", (tmp.path / "merged").string(), "--json"});
  REQUIRE(r.exit_code == 0);
  const json o = json::parse(r.out);
  CHECK(o["points"] == 18);
  CHECK(o["shards"] == 3);
  CHECK(o["file"] == (tmp.path / "merged" / "field.json").string());
  CHECK(field_values(tmp.path / "merged") == field_values(tmp.path / "serial"));
  CHECK(fs::exists(tmp.path / "merged" / "field_table.csv"));
  // The contract's form, `pdamp field merge DIR...` (docs/command_line.md): the case from the first
  // folder's shard_case.json, the source from its log; the same field.
  const auto bare = run_pdamp({"field", "merge", shards[1], shards[2], shards[0], "-o", (tmp.path / "by_dirs").string(),
                               "--json"});
  INFO(bare.err);
  REQUIRE(bare.exit_code == 0);
  CHECK(json::parse(bare.out)["points"] == 18);
  CHECK(field_values(tmp.path / "by_dirs") == field_values(tmp.path / "serial"));
  // A folder without the case: exit 2 telling how to give it.
  fs::remove(tmp.path / shard_folder(1) / "shard_case.json");
  require_one_line_error(run_pdamp({"field", "merge", shards[1], shards[2], shards[0], "-o", (tmp.path / "x").string()}),
                         "holds no shard_case.json");
}

TEST_CASE("pdamp field merge refuses shards of another case, grid or model version naming both files", "[cli]") {
  TempDir tmp("field_shards_mismatch");
  const std::string c = shard_case("pdamp_shards_mismatch.json");
  const fs::path s0 = run_shard(c, tmp.path, 0, 2);
  const std::string log0 = (s0 / "field_sweep.jsonl").string();
  const auto merge = [&](const fs::path& other) {
    return run_pdamp({"field", "merge", c, "--source", "formulas", s0.string(), other.string(), "-o",
                      (tmp.path / "merged").string()});
  };
  SECTION("another case") {
    const std::string bouncing = shard_case("pdamp_shards_bouncing.json", [](json& j) { j["damper"]["model"] = "bouncing"; });
    const fs::path s1 = run_shard(bouncing, tmp.path / "b", 1, 2);
    const auto r = merge(s1);
    require_one_line_error(r, log0 + " and " + (s1 / "field_sweep.jsonl").string() + ": are not shards of one sweep (case_hash");
  }
  SECTION("another grid") {
    const std::string wider = shard_case("pdamp_shards_wider.json", [](json& j) { j["field"]["axis0"]["max"] = 3.0; });
    const fs::path s1 = run_shard(wider, tmp.path / "w", 1, 2);
    require_one_line_error(merge(s1), log0 + " and " + (s1 / "field_sweep.jsonl").string() + ": are not shards of one sweep (axes");
  }
  SECTION("another model version") {
    const fs::path s1 = run_shard(c, tmp.path, 1, 2);
    const fs::path log1 = s1 / "field_sweep.jsonl";
    std::string text = slurp(log1);
    text.replace(text.find("\"model_version\":0"), 17, "\"model_version\":7");
    std::ofstream(log1, std::ios::binary | std::ios::trunc) << text;
    require_one_line_error(merge(s1), log0 + " and " + log1.string() + ": are not shards of one sweep (model_version: " +
                                          log0 + " 0, " + log1.string() + " 7)");
  }
  SECTION("shards of another case than the one given") {
    const fs::path s1 = run_shard(c, tmp.path, 1, 2);
    const std::string bouncing = shard_case("pdamp_shards_bouncing.json", [](json& j) { j["damper"]["model"] = "bouncing"; });
    const auto r = run_pdamp({"field", "merge", bouncing, "--source", "formulas", s0.string(), s1.string(), "-o",
                              (tmp.path / "merged").string()});
    require_one_line_error(r, log0 + ": line 1: is a shard of another sweep than " + bouncing + " (case_hash");
  }
  CHECK(!fs::exists(tmp.path / "merged" / "field.json"));
}

TEST_CASE("pdamp field merge refuses a missing, repeated or damaged shard and a shard's folder as output", "[cli]") {
  TempDir tmp("field_shards_refused");
  const std::string c = shard_case("pdamp_shards_missing.json");
  std::vector<std::string> s;
  for (int i = 0; i < 3; ++i) s.push_back(run_shard(c, tmp.path, i, 3).string());
  const std::string out = (tmp.path / "merged").string();
  const auto merge = [&](std::vector<std::string> shards, const std::string& dir) {
    std::vector<std::string> args{"field", "merge", c, "--source", "formulas", "-o", dir};
    args.insert(args.end(), shards.begin(), shards.end());
    return run_pdamp(args);
  };
  require_one_line_error(merge({s[0], s[2]}, out), "shard 1 of 3 is missing");
  require_one_line_error(merge({s[0], s[1], s[2], s[1]}, out), "both are shard 1/3");
  require_one_line_error(merge({s[0], s[1], s[2]}, s[1]), "-o: '" + s[1] + "' holds the shard file");
  CHECK(fs::exists(fs::path(s[1]) / "field_sweep.jsonl"));
  require_one_line_error(merge({s[0]}, out), "shards 1, 2 of 3 are missing");

  // A damaged line: refused with its line number by the sweep log's reader.
  const fs::path log = fs::path(s[2]) / "field_sweep.jsonl";
  std::string text = slurp(log);
  const std::size_t line3 = text.find('\n', text.find('\n') + 1) + 1;
  text.insert(line3, "{\"index\": oops}\n");
  std::ofstream(log, std::ios::binary | std::ios::trunc) << text;
  require_one_line_error(merge({s[0], s[1], s[2]}, out), log.string() + ": line 3: malformed JSON");
  require_one_line_error(merge({s[0], s[1], (tmp.path / "nowhere").string()}, out), "nowhere");
  CHECK(!fs::exists(fs::path(out) / "field.json"));
  // Wrong source, no shard at all.
  require_one_line_error(run_pdamp({"field", "merge", c, "--source", "measured", s[0]}), "--source: 'measured'");
  require_one_line_error(run_pdamp({"field", "merge", c, "--source", "formulas"}), "no shard given");
}

TEST_CASE("rerunning a shard resumes its log, and a log of another shard is refused", "[cli]") {
  TempDir tmp("field_shards_resume");
  const std::string c = shard_case("pdamp_shards_resume.json");
  const fs::path s1 = run_shard(c, tmp.path, 1, 3);
  const fs::path log = s1 / "field_sweep.jsonl";
  // Drop the last point, as a killed job would leave it: the rerun computes only that one.
  std::string text = slurp(log);
  text.erase(text.rfind('\n', text.size() - 2) + 1);
  std::ofstream(log, std::ios::binary | std::ios::trunc) << text;
  const auto again = run_pdamp({"field", c, "--source", "formulas", "--shard", "1/3", "-o", s1.string(), "--json"});
  REQUIRE(again.exit_code == 0);
  CHECK_THAT(json::parse(again.out)["sweep"].get<std::string>(), Catch::StartsWith("6 points: 5 resumed, 1 computed"));
  const auto other = run_pdamp({"field", c, "--source", "formulas", "--shard", "2/3", "-o", s1.string()});
  require_one_line_error(other, "belongs to another sweep");
  CHECK(slurp(log).find("\"shard\":{\"count\":3,\"index\":1}") != std::string::npos);
}

TEST_CASE("bad --shard values are refused with the allowed range", "[cli]") {
  const std::string c = shard_case("pdamp_shards_bad_flag.json");
  for (const char* bad : {"3/3", "-1/3", "1/0", "0/100001", "a/b", "1", "1/2/3", "/3", "1/", " 1/3", "1.0/3", "+1/3"}) {
    INFO(bad);
    require_one_line_error(run_pdamp({"field", c, "--source", "formulas", "--shard", bad, "-o",
                                      (fs::temp_directory_path() / "pdamp_bad_shard").string()}),
                           "--shard: '" + std::string(bad) + "': must be I/N with whole numbers 0 <= I < N <= 100000");
  }
  require_one_line_error(run_pdamp({"field", c, "--source", "measured", "--measured", "x.csv", "--shard", "0/2"}),
                         "--shard: goes with --source dem or formulas");
}
