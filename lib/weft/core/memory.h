#pragma once
/// @file
/// @brief Memory budgets and byte counts in messages: what every "estimate before spending"
/// guard (voxelizer, cloth generator, local fields) compares against and prints.

#include <cstdint>
#include <string>
#include <utility>

namespace weft {

/// Half the memory the process may use (the default budget of every guard): half the physical RAM
/// (4 GiB when it cannot be read), or half the address-space limit (`ulimit -v`) when that is
/// smaller, since an allocation past the limit fails however much RAM there is.
std::uint64_t default_memory_budget();

/// @brief A memory limit given in MiB (`--max-memory`, `export --max-memory-mb`, Python's
/// `max_memory_mb=`) in bytes: 0 is default_memory_budget(); any other limit is rounded up, so a
/// tiny one stays a limit (1 byte) instead of reading as 0, the guards' "default", and saturates
/// at 2^64 - 1. Throws weft::Error (naming `what`) for a NaN, infinite or negative `mib`: the
/// front ends refuse those first, as usage errors.
std::uint64_t memory_budget_bytes(const char* what, double mib);

/// A byte count for a message, in the unit that keeps it readable ("812 bytes", "3.4 KiB",
/// "27.1 MiB", "2.05 GiB", up to EiB: "3.05 PiB"); a small budget never reads as "0.0 MiB".
std::string format_bytes(std::uint64_t bytes);

/// Two byte counts said side by side ("needs X, over the budget of Y"): format_bytes of each or,
/// when those read the same, both in the smaller one's unit with as many decimals as it takes for
/// the texts to differ when the counts do (6.52 MiB against 6.50 MiB, not "6.5 MiB, over the
/// budget of 6.5 MiB"), exact bytes at the end.
std::pair<std::string, std::string> format_bytes_apart(std::uint64_t a, std::uint64_t b);

}  // namespace weft
