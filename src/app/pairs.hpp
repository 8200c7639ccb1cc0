#pragma once
// The effective contact parameters of every pair of materials that can touch in a case
// (grain-grain, grain-wall, grain-interface): what `fdem check` prints, run.json records and
// the set-up warnings are made from. The combination rules (MaterialTable, dem/material.cpp):
// friction the smaller of the two (YADE's FrictMat), K_T/K_N the mean, beta_r and eta_r the mean
// (incremental rolling law) or the larger (total law: one beta_r for every pair, as the
// thesis's engine), each unless an `interactions` entry overrides it; the rolling law the two
// materials' (`interactions` when they differ); the contact model the case's `contact_model`
// (linear by default) unless an `interactions` entry names one.
#include <string>
#include <vector>

#include "io/case.hpp"
#include "io/run_info.hpp"

namespace fdem {

/// One pair of materials that can touch, with the parameters the contact law uses.
struct ContactPair {
  int grain = -1, other = -1;   // material indices: a particle material and what it touches
  std::string touch;            // "grain-grain", "grain-wall (names)", "grain-interface"
  PairParams p;                 // effective
  bool friction_set = false, kt_kn_set = false, beta_r_set = false, eta_r_set = false,
       model_set = false, rolling_set = false;  // by `interactions`
};

/// The pairs of materials that can touch in this case, in a fixed order: grain-grain, then
/// grain-wall, then grain-interface. Particle materials: those of the particle sources and of
/// the packing (every material when neither names one, e.g. a restart).
std::vector<ContactPair> contact_pairs(const CaseConfig& c);

/// The pair table as text lines (for `fdem check`), one header line first.
std::vector<std::string> pair_table_lines(const CaseConfig& c);

/// The pair table for run.json.
std::vector<PairRecord> pair_records(const CaseConfig& c);

/// Set-up warnings ("file:line: warning: ..."): a material friction that no pair that can touch
/// uses (undercut by the smaller one, or overridden), naming the `interactions` entry that would
/// apply it; a material that nothing uses.
std::vector<std::string> pair_warnings(const CaseConfig& c);

}  // namespace fdem
