// The readers of untrusted files, fed bytes: shared by the libFuzzer targets (tests/fuzz/)
// and the regression test of the inputs they found (tests/case_file/test_fuzz_regressions.cpp).
//
// Contract checked (docs/bad_inputs.md): whatever the bytes, a reader either accepts the
// file or throws std::invalid_argument (base::InputError, case_file::CaseError,
// structure::ModalDataError and the readers' own std::invalid_argument are all of that
// class, which the CLI maps to exit 2) with a message on one printable line that names
// the file. Any other exception, a message that breaks the line, a sanitizer report or a
// hang is a bug.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <typeinfo>
#include <vector>

#include "reader_kind.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/formulas/cor_models.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/imported_modal_data.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/grid.hpp"
#include "pdamp/surrogate/measured_import.hpp"
#include "pdamp/surrogate/scattered_fit.hpp"
#include "pdamp/surrogate/sweep.hpp"

namespace pdamp::fuzz {

namespace fs = std::filesystem;


struct ReaderInfo {
  Reader reader;
  std::string_view name;
  std::string_view file_name;
  /// Whether every error must quote the file name (a case may name other files, its
  /// modal data or a path it gives, whose errors name those instead).
  bool names_its_file;
};

inline constexpr ReaderInfo kReaders[] = {
    {Reader::kCaseFile, "case_file", "case.json", false},
    {Reader::kFieldFile, "field_file", "field.json", true},
    {Reader::kMeasuredCsv, "measured_csv", "measured.csv", true},
    {Reader::kImpactCsv, "impact_csv", "impacts.csv", true},
    {Reader::kScatteredFit, "scattered_fit", "scattered_fit.json", true},
    {Reader::kModalData, "modal_data", "modal.json", true},
    {Reader::kSweepLog, "sweep_log", "field_sweep.jsonl", true},
    {Reader::kShardLog, "shard_log", "field_sweep.jsonl", true},
    {Reader::kCheckpoint, "checkpoint", "decay_dem.checkpoint", true},
};

inline const ReaderInfo& info(Reader reader) {
  for (const auto& r : kReaders)
    if (r.reader == reader) return r;
  std::abort();
}

/// What one input did: accepted, refused cleanly (`error`), or broke the contract (`problem`).
struct Outcome {
  bool accepted = false;
  std::string error;    ///< what() of the clean refusal
  std::string problem;  ///< non-empty: the contract is broken (the fuzzer aborts on it)
};

/// The grid of the sweep-log reader; its header is in tests/fuzz/corpus/sweep_log/.
inline surrogate::Grid sweep_grid() {
  using namespace surrogate;
  return Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 3.0, 2, AxisSpacing::kLinear},
                           {0.005, 0.04, 2, AxisSpacing::kLog});
}

inline surrogate::SweepOptions sweep_options(const fs::path& results) {
  surrogate::SweepOptions options;
  options.results_path = results;
  options.source = surrogate::FieldSource::kDem;
  options.case_hash = "f00dfeedc0ffee00";
  options.model_version = 1;
  options.clearance_m = 0.04;
  options.bed_mass_kg = 0.74;
  options.threads = 1;
  return options;
}

/// The structure and bed of the checkpoint reader (its seed, tests/fuzz/corpus/checkpoint/,
/// is a free decay of this model; tests/fuzz/make_checkpoint_seed.cpp writes it): one mode
/// at 10 Hz, four spheres in a box at the point "tip".
inline structure::ModalModel checkpoint_model() {
  structure::ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, 10.0);
  m.damping_ratios = Eigen::VectorXd::Constant(1, 0.01);
  m.modal_masses_kg = Eigen::VectorXd::Constant(1, 0.1);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, 1.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Constant(1, 0.0)}};
  return m;
}

inline std::vector<structure::CosimulationDamper> checkpoint_dampers() {
  dem_reference::WorldOptions w;
  w.materials[0].material.youngs_modulus_pa = 2e8;
  w.gravity_m_s2 = {0.0, 0.0, -9.80665};
  auto& c = w.compartments[0];
  c.container.box_inner_size_m = {0.03, 0.0201, 0.0201};
  c.placement = dem_reference::InitialPlacement::kCollectedLattice;
  c.lattice_counts = {1, 2, 2};
  c.particles[0].radius_m = 0.005;
  c.particles[0].count = 4;
  c.particles[0].lot_diameter_variation_m = 0.0;
  structure::CosimulationDamper d;
  d.name = "tip";
  d.point = "tip";
  d.drive_direction = {0.0, 1.0};
  d.container_mass_kg = 0.02;
  d.world = w;
  return {d};
}

/// A folder for the inputs of one process (tmpfs when there is one: a fuzzer writes
/// a file per execution), holding the files the shipped cases' seeds name beside them.
class InputFolder {
 public:
  explicit InputFolder(std::string_view tag) {
    const fs::path base = fs::is_directory("/dev/shm") && ::access("/dev/shm", W_OK) == 0 ? fs::path("/dev/shm")
                                                                                          : fs::temp_directory_path();
    path_ = base / ("pdamp_fuzz_" + std::string(tag) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
#ifdef PDAMP_SOURCE_DIR
    // Format-2 seeds name their modal data relative to themselves.
    for (const char* name : {"one_mode_tip.json", "one_mode_dem.json"}) {
      std::error_code ignored;
      for (const char* folder : {"tests/case_file/data/", "tests/cli/data/"})
        fs::copy_file(fs::path(PDAMP_SOURCE_DIR) / folder / name, path_ / name, fs::copy_options::skip_existing,
                      ignored);
    }
#endif
  }
  ~InputFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  InputFolder(const InputFolder&) = delete;
  InputFolder& operator=(const InputFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// The message of a clean refusal: non-empty, one line of printable text (valid UTF-8
/// may stay, as base::printable leaves it) naming the file when `file` is given.
inline std::string message_problem(const std::string& what, std::string_view file) {
  if (what.empty()) return "empty error message";
  for (const char c : what) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7F) return "error message holds control byte " + std::to_string(byte);
  }
  if (!file.empty() && what.find(file) == std::string::npos)
    return "error message does not name the file " + std::string(file);
  return "";
}

/// Saves `bytes` in `folder` and feeds them to `reader`.
inline Outcome feed(Reader reader, const fs::path& folder, std::string_view bytes) {
  const ReaderInfo& r = info(reader);
  const fs::path path = folder / r.file_name;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) return {false, "", "cannot write the input file " + path.string()};
  }
  Outcome outcome;
  try {
    switch (reader) {
      case Reader::kCaseFile: (void)case_file::load_case(path.string()); break;
      case Reader::kFieldFile: (void)surrogate::read_effective_field(path); break;
      case Reader::kMeasuredCsv: {
        surrogate::MeasuredImportOptions options;
        options.clearance_m = 0.1;
        options.bed_mass_kg = 0.148;
        (void)surrogate::import_measured_csv(path, options);
        break;
      }
      case Reader::kImpactCsv: (void)formulas::read_impact_csv(path.string()); break;
      case Reader::kScatteredFit: (void)surrogate::read_scattered_fit(path); break;
      case Reader::kModalData: {
        const auto document = base::parse_json_document(base::read_input_file(path.string()), path.string());
        try {
          (void)structure::modal_model_from_json(document);
        } catch (const structure::ModalDataError& e) {
          // Its what() is "<pointer>: <rule>"; the case reader prefixes the file.
          throw std::invalid_argument(path.string() + ": " + e.what());
        }
        break;
      }
      case Reader::kSweepLog: (void)surrogate::pending_sweep_points(sweep_grid(), sweep_options(path)); break;
      case Reader::kShardLog:  // pdamp field merge of one shard file: its header checks, then the lines
        (void)surrogate::merge_sweep_shards(sweep_grid(), sweep_options(path), {path}, "the fuzzed sweep");
        break;
      case Reader::kCheckpoint: {  // pdamp decay --method dem --resume: the file, then the state it carries
        const std::string bytes = base::read_input_file(path.string(), dem_reference::kMaxCheckpointBytes);
        const auto restore = [](std::string_view payload) {
          dem_reference::StateReader in(payload, "checkpoint state");
          (void)structure::restore_cosimulation_state(checkpoint_model(), checkpoint_dampers(), in);
          (void)structure::restore_cosimulation_result(in, 1, 1);
          in.finish();
        };
        // The state reader on whatever follows the header line, as if its hash were right: a
        // mutation rarely keeps the FNV-1a hash, and the reader behind it must hold anyway.
        if (const auto header_end = bytes.find('\n', bytes.find('\n') + 1); header_end != std::string::npos) {
          try {
            restore(std::string_view(bytes).substr(header_end + 1));
          } catch (const std::invalid_argument&) {
            // refused cleanly: the contract of this path (the CLI path below names the file)
          }
        }
        const auto decoded = dem_reference::decode_checkpoint(bytes, path.string());
        try {
          restore(decoded.payload);
        } catch (const base::InputError&) {
          throw;
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(path.string() + ": " + e.what());  // as the CLI names the file
        }
        break;
      }
    }
    outcome.accepted = true;
  } catch (const std::invalid_argument& e) {
    outcome.error = e.what();
    outcome.problem = message_problem(outcome.error, r.names_its_file ? r.file_name : std::string_view());
    if (!outcome.problem.empty()) outcome.problem += ": " + base::printable(outcome.error);
  } catch (const std::exception& e) {
    outcome.problem = std::string("threw ") + typeid(e).name() + " (not std::invalid_argument): " +
                      base::printable(e.what());
  } catch (...) {
    outcome.problem = "threw something that is not a std::exception";
  }
  return outcome;
}

/// The body of every fuzz target (fuzz_one_input.cpp): a broken contract aborts, so
/// libFuzzer saves the input.
inline void fuzz_one(Reader reader, const std::uint8_t* data, std::size_t size) {
  static const InputFolder folder(info(reader).name);
  const Outcome outcome = feed(reader, folder.path(), {reinterpret_cast<const char*>(data), size});
  if (!outcome.problem.empty()) {
    std::fprintf(stderr, "pdamp fuzz_%s: contract broken: %s\n", std::string(info(reader).name).c_str(),
                 outcome.problem.c_str());
    std::abort();
  }
}

}  // namespace pdamp::fuzz
