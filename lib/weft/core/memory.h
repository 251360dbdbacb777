#pragma once
/// @file
/// @brief Memory budgets and byte counts in messages: what every "estimate before spending"
/// guard (voxelizer, cloth generator, local fields) compares against and prints.

#include <cstdint>
#include <string>

namespace weft {

/// Half the memory the process may use (the default budget of every guard): half the physical RAM
/// (4 GiB when it cannot be read), or half the address-space limit (`ulimit -v`) when that is
/// smaller, since an allocation past the limit fails however much RAM there is.
std::uint64_t default_memory_budget();

/// A byte count for a message, in the unit that keeps it readable ("812 bytes", "3.4 KiB",
/// "27.1 MiB", "2.05 GiB"); a small budget never reads as "0.0 MiB".
std::string format_bytes(std::uint64_t bytes);

}  // namespace weft
