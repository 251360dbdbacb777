#pragma once
/// @file
/// @brief `weft validate --corpus`: the corpus study's front-end (outputs, table, figure).

#include <cstdint>
#include <string>
#include <vector>

#include "command.h"

namespace weft::app {

struct CorpusOptions {
  std::string out;
  bool no_plot = false;
  bool quick = false;
  bool resume = false;
  std::uint64_t seed = 1;
  std::string window = "yarn";
  std::vector<std::string> cases;  ///< name parts (--cases); empty: every case
};

/// Runs every case of study::corpus_cases (spread over MPI ranks; finished cases recorded in
/// OUT/units/ for --resume), writes corpus.csv, corpus.json and corpus.png on rank 0.
int run_corpus(const CorpusOptions& o, const Context& ctx);

}  // namespace weft::app
