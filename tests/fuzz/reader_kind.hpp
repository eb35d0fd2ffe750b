// Which reader a fuzz target feeds: the small part of fuzz_readers.hpp that each target's
// own file (fuzz_target.cpp) needs, so that the readers are compiled once
// (fuzz_one_input.cpp) for the nine targets instead of once each.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pdamp::fuzz {

/// One reader of a user's file (fuzz_readers.hpp, kReaders: the fuzz target's suffix
/// fuzz_<name>, the folder of its corpus and regressions, the file name the bytes get).
enum class Reader {
  kCaseFile,
  kFieldFile,
  kMeasuredCsv,
  kImpactCsv,
  kScatteredFit,
  kModalData,
  kSweepLog,
  kShardLog,
  kCheckpoint
};

/// fuzz_one of fuzz_readers.hpp: the input fed to the reader; aborts on a broken contract.
void fuzz_one_input(Reader reader, const std::uint8_t* data, std::size_t size);

}  // namespace pdamp::fuzz
