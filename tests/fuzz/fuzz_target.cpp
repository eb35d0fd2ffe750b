// One libFuzzer target: the reader named by PDAMP_FUZZ_READER (a pdamp::fuzz::Reader
// enumerator, set per target by tests/fuzz/CMakeLists.txt) fed each input.
#include <cstddef>
#include <cstdint>

#include "reader_kind.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pdamp::fuzz::fuzz_one_input(pdamp::fuzz::Reader::PDAMP_FUZZ_READER, data, size);
  return 0;
}
