// The inputs the fuzz targets found (tests/data/fuzz_regressions/<reader>/) and their seeds
// (tests/fuzz/corpus/<reader>/), fed to the readers through the normal build: each is
// accepted or refused with one clean line (std::invalid_argument naming the file), never
// another exception. A file named refused_* must be refused, accepted_* accepted.
#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fuzz_readers.hpp"

namespace {

namespace fs = std::filesystem;
using pdamp::fuzz::feed;
using pdamp::fuzz::InputFolder;
using pdamp::fuzz::kReaders;
using pdamp::fuzz::Outcome;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

/// Regular files under `folder`, sorted (none if it does not exist).
std::vector<fs::path> files_in(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

const fs::path kSource = PDAMP_SOURCE_DIR;

}  // namespace

TEST_CASE("every input the fuzzers found is accepted or refused on one clean line", "[case_file]") {
  InputFolder folder("regressions");
  std::size_t inputs = 0;
  for (const auto& reader : kReaders) {
    for (const fs::path& file : files_in(kSource / "tests/data/fuzz_regressions" / reader.name)) {
      ++inputs;
      const std::string name = file.filename().string();
      INFO(std::string(reader.name) + ": " + name);
      const Outcome outcome = feed(reader.reader, folder.path(), read_bytes(file));
      CHECK(outcome.problem.empty());
      if (name.rfind("refused_", 0) == 0) CHECK_FALSE(outcome.accepted);
      if (name.rfind("accepted_", 0) == 0) CHECK(outcome.accepted);
    }
  }
  // The folder holds at least one input per bug fixed (docs/bad_inputs.md, "Fuzzing").
  CHECK(inputs > 0);
}

TEST_CASE("the fuzzers' seeds are fed cleanly and the valid ones are accepted", "[case_file]") {
  InputFolder folder("seeds");
  for (const auto& reader : kReaders) {
    const auto seeds = files_in(kSource / "tests/fuzz/corpus" / reader.name);
    INFO(reader.name);
    CHECK(!seeds.empty());
    for (const fs::path& seed : seeds) {
      INFO(seed.filename().string());
      const Outcome outcome = feed(reader.reader, folder.path(), read_bytes(seed));
      INFO(outcome.error);
      CHECK(outcome.problem.empty());
      // Every seed is a valid file of its kind: a seed the reader refuses teaches the
      // fuzzer little beyond the first error.
      CHECK(outcome.accepted);
    }
  }
}

TEST_CASE("the harness calls a broken message a problem and a clean refusal clean", "[case_file]") {
  using pdamp::fuzz::message_problem;
  CHECK(message_problem("field.json: /axes: missing (required key)", "field.json").empty());
  CHECK(message_problem("caf\xc3\xa9.json: no such file", "").empty());  // UTF-8 stays
  CHECK_FALSE(message_problem("field.json: line one\nline two", "field.json").empty());
  CHECK_FALSE(message_problem("field.json: a \x1b[31m escape", "field.json").empty());
  CHECK_FALSE(message_problem("/axes: missing", "field.json").empty());
  CHECK_FALSE(message_problem("", "").empty());

  InputFolder folder("harness");
  // A cut JSON file: the reader's own clean error, naming the file.
  const Outcome refused = feed(pdamp::fuzz::Reader::kFieldFile, folder.path(), "{\"format\": 1");
  CHECK_FALSE(refused.accepted);
  CHECK(refused.problem.empty());
  CHECK_THAT(refused.error, Catch::Contains("field.json") && Catch::Contains("malformed JSON"));
}
