// FNV-1a, 64 bits (Fowler, Noll and Vo): a fast hash that tells damaged or mismatched bytes
// (a checkpoint's payload, a job set up from other inputs). Not for an adversary.
#pragma once

#include <cstdint>
#include <string_view>

namespace pdamp::base {

inline std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t hash = 14695981039346656037ULL;  // the FNV offset basis
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;  // the FNV prime
  }
  return hash;
}

}  // namespace pdamp::base
