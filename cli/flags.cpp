// Flags several subcommands share (flags.hpp).
#include "flags.hpp"

#include <cstdlib>

#include "errors.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"

namespace pdamp::cli {

const FlagSpec kJsonFlag{"--json", "", "print exactly one JSON object on stdout"};
const FlagSpec kOutFlag{"-o", "DIR", "write result files (JSON, CSV, plots) into DIR, atomically"};
const FlagSpec kOverwriteFlag{"--overwrite", "",
                              "let -o DIR replace the outputs another command or case left there (refused otherwise)"};

const FlagSpec kMethodFlag{"--method", "M",
                           "source of each layer's eta*(f, X) and apparent mass: formulas (the closed\n"
                           "                          forms of its model and clearance; default), field (the\n"
                           "                          layer's field_file, made by pdamp field) or dem (frf and\n"
                           "                          decay only: the structure co-simulated in time with each\n"
                           "                          damper's bed as a DEM world, the case's dem settings)"};

const std::vector<FlagSpec> kDemSweepFlags{
    {"--dem-points", "N",
     "--method dem: frequencies of the stepped sine, linear over its band,\n"
     "                          [2, 1000] (default 9)"},
    {"--dem-min-frequency", "HZ", "--method dem: lowest frequency of the stepped sine, Hz, > 0\n"
                                  "                          (default: the task's min_frequency_hz)"},
    {"--dem-max-frequency", "HZ", "--method dem: highest frequency of the stepped sine, Hz, above the\n"
                                  "                          lowest (default: the task's max_frequency_hz)"},
    {"--dem-sweep", "D", "--method dem: up, down or both (default both: the two directions\n"
                         "                          run in parallel on a machine of two or more cores)"},
    {"--dem-signal", "S", "--method dem: stepped (a stepped sine, default) or linear (a linear sine\n"
                          "                          sweep over the band, from the steady state at its start)"},
    {"--dem-tolerance", "TOL", "--method dem: a point's transient has converged when, over the last 8\n"
                               "                          periods, every period-to-period change of the site amplitude\n"
                               "                          and its change across them are at most TOL of their mean,\n"
                               "                          (0, 0.99] (default 0.05)"},
    {"--dem-max-periods", "N", "--method dem: most transient periods per point, [0, 100000] (default 200,\n"
                               "                          at least the case's dem.transient_periods); a point not\n"
                               "                          converged by then is analysed, marked and warned"},
    {"--dem-sweep-rate", "HZ/S", "--dem-signal linear: the sweep's rate, Hz/s, > 0 (default: 4 pi zeta^2 f^2 / 100\n"
                                 "                          at the formulas' resonance: quasi-stationary)"}};

const FlagSpec kAcceptLongRunFlag{"--accept-long-run", "",
                                  "start a DEM run whose estimated wall time is beyond a week (refused\n"
                                  "                          otherwise, naming the keys that shorten it)"};

const std::vector<FlagSpec> kCheckpointFlags{
    {"--resume", "", "continue the DEM run from its checkpoint in the -o folder (left by a run that\n"
                     "                          was interrupted or killed; same case, settings and thread count)"},
    {"--checkpoint-interval", "S", "wall-clock seconds between checkpoints of a DEM run in the -o folder,\n"
                                   "                          >= 0 (default 60; 0: after every segment of about 2 s); one is\n"
                                   "                          also written when SIGINT, SIGTERM or SIGHUP arrives"},
    kAcceptLongRunFlag};

const FlagSpec kNoVerifyFlag{"--no-verify", "",
                             "skip the DEM verification the task's verify block asks for (the optimisation only)"};

const FlagSpec kCalibrationCacheFlag{"--calibration-cache", "DIR",
                                     "calibrated beds (filling_ratios) and modes: the folder of their cache\n"
                                     "                          files (default ~/.cache/pdamp/bed_calibration)"};

case_file::LossMethod loss_method(const ParsedArgs& args, const std::string& command) {
  const std::string name = args.optional_text("--method").value_or("formulas");
  if (name == "formulas") return case_file::LossMethod::kFormulas;
  if (name == "field") return case_file::LossMethod::kField;
  if (name == "dem")
    throw InputError("--method", "", "'dem': " + command + " takes formulas or field (the DEM co-simulation runs in "
                                     "pdamp frf and pdamp decay)");
  throw InputError("--method", "", "'" + name + "': must be formulas, field or dem");
}

bool dem_method(const ParsedArgs& args) { return args.optional_text("--method").value_or("") == "dem"; }

tasks::CheckpointFile checkpoint_file(const ParsedArgs& args, const std::string& name) {
  tasks::CheckpointFile out;
  out.resume = args.has("--resume");
  (void)checkpoint_interval(args);  // a bad interval is refused before any work
  const auto dir = args.optional_text("-o");
  if (!dir) {
    if (out.resume) throw InputError("--resume", "", "needs -o DIR: the checkpoint is in the output folder");
    return out;
  }
  out.path = std::filesystem::path(*dir) / (name + ".checkpoint");
  // Whatever is in the way (a link that loops or leads nowhere, a folder) is the user's to
  // move: named now, before any work, not as a raw filesystem error at the first write.
  std::error_code error, link_error;
  const auto status = std::filesystem::status(out.path, error);
  const bool missing = error == std::errc::no_such_file_or_directory ||
                       (!error && status.type() == std::filesystem::file_type::not_found);
  const bool dangling = std::filesystem::is_symlink(std::filesystem::symlink_status(out.path, link_error)) && missing;
  if (dangling || (!missing && (error || !std::filesystem::is_regular_file(status))))
    throw InputError("-o", "", "'" + base::printable(out.path.string()) + "' is in the way of the checkpoint (" +
                                   (dangling ? std::string("a link to nothing")
                                             : error ? error.message() : std::string("not a regular file")) +
                                   "): move it away");
  return out;
}

double checkpoint_interval(const ParsedArgs& args) {
  return args.optional_number("--checkpoint-interval", Range{0.0, 1e9}).value_or(60.0);
}

std::vector<std::string> length_scale_warnings(const ParsedArgs& args, const std::vector<std::string>& flags) {
  std::vector<std::string> warnings;
  for (const auto& flag : flags) {
    const auto text = args.optional_text(flag);
    if (!text) continue;
    const double metres = std::strtod(text->c_str(), nullptr);  // already checked by the command
    if (metres > 1.0)
      warnings.push_back(flag + " " + *text + " is " + *text + " m, larger than any particle damper's (millimetres to "
                         "decimetres): flags take metres (" + base::format_number(metres / 1000.0) + " for " +
                         *text + " mm)");
  }
  return warnings;
}

void refuse_flags(const ParsedArgs& args, const std::vector<FlagSpec>& flags, const std::string& why) {
  for (const auto& flag : flags)
    if (args.has(flag.name)) throw InputError(flag.name, "", why);
}

void refuse_checkpoint_flags(const ParsedArgs& args, const std::string& why) { refuse_flags(args, kCheckpointFlags, why); }

}  // namespace pdamp::cli
