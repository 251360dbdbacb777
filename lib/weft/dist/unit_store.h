#pragma once
/// @file
/// @brief Finished work units on disk, so a long run that dies can be resumed (`--resume`).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "weft/core/front_end.h"
#include "weft/dist/distributed.h"

namespace weft::dist {

/// @brief A folder of finished units: `run.json` (what run they belong to) and one file per unit
/// (`unit-000042.bin`, written atomically: a unit is there whole or not at all).
///
/// Only rank 0 touches the folder, and only from inside run_units (so an error — a folder of
/// another run, a full disk — reaches every rank as a UnitFailure instead of leaving the others
/// waiting). A fresh run (resume = false) empties the folder first; a resumed run checks that
/// `run.json` holds the same key and keeps the units it finds.
class UnitStore {
 public:
  /// `key` identifies the run (e.g. its options as JSON): units of a different key are refused,
  /// naming the resume option as `front` spells it (`--resume`, Python's `resume=True`).
  UnitStore(std::filesystem::path folder, std::string key, bool resume, FrontEnd front = FrontEnd::cli);

  /// @brief Creates or checks the folder (called by run_units on rank 0).
  void open();
  /// @brief The unit's bytes if a previous run of the same key finished it.
  [[nodiscard]] std::optional<Bytes> load(std::size_t unit) const;
  /// @brief Records a finished unit atomically.
  void save(std::size_t unit, const Bytes& bytes) const;
  /// @brief Removes the folder once the run's outputs are written (rank 0; no-op elsewhere).
  void remove() const;

  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
  [[nodiscard]] bool resume() const { return resume_; }
  [[nodiscard]] FrontEnd front_end() const { return front_; }
  /// Units found on disk by open() (0 for a fresh run).
  [[nodiscard]] std::size_t found() const { return found_; }
  void set_found(std::size_t n) { found_ = n; }

 private:
  [[nodiscard]] std::filesystem::path unit_path(std::size_t unit) const;
  std::filesystem::path folder_;
  std::string key_;
  bool resume_;
  FrontEnd front_;
  std::size_t found_ = 0;
};

}  // namespace weft::dist
