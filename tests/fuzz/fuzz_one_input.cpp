// The readers for every fuzz target, compiled once (reader_kind.hpp).
#include "fuzz_readers.hpp"

namespace pdamp::fuzz {

void fuzz_one_input(Reader reader, const std::uint8_t* data, std::size_t size) { fuzz_one(reader, data, size); }

}  // namespace pdamp::fuzz
