#pragma once
// Ghost layers and migration for the DEM particles (DESIGN.md section 3).
//
// Halo: owned -> ghost copies. exchange() rebuilds the ghost layer from scratch in three sweeps
// (x, then y, then z; particles received in an earlier sweep are forwarded in later ones, so
// edge and corner neighbours are covered without diagonal messages) and remembers what it sent;
// update() refreshes the ghosts' positions, velocities and angular velocities along the same
// plan every step. Ghost width = cutoff >= 2 r_max + skin.
//
// Distributor: ownership changes at rebuild. migrate() sends owned particles whose centre left
// the subdomain to the neighbour in that direction (three sweeps, repeated until none moves),
// together with every contact-history record that involves them.
//
// Messages: MPI_Sendrecv of packed doubles between face neighbours only. Counters of bytes and
// messages sent are kept for the run summary.
#include <cstdint>
#include <vector>

#include "dem/contact_history.hpp"
#include "dem/particles.hpp"
#include "partition/decomposition.hpp"

namespace fdem {

struct CommStats {
  std::uint64_t bytes = 0, messages = 0;
};

class Halo {
 public:
  /// Drop existing ghosts and build a new ghost layer of width `cutoff`.
  void exchange(const Decomposition& dd, ParticleStore& p, double cutoff);
  /// Refresh ghost x, v, w along the plan of the last exchange().
  void update(const Decomposition& dd, ParticleStore& p);
  CommStats stats;

 private:
  struct Sweep {
    std::vector<std::size_t> send_lo, send_hi;  // local indices sent down / up
    std::size_t recv_lo_begin = 0, recv_lo_n = 0;  // ghosts received from below
    std::size_t recv_hi_begin = 0, recv_hi_n = 0;  // ghosts received from above
  };
  Sweep sweeps_[3];
  std::size_t ghosts_last_ = 0;  // ghosts of the last exchange (the next one's room)
  std::vector<double> sbuf_lo_, sbuf_hi_, rbuf_lo_, rbuf_hi_;
};

class Distributor {
 public:
  /// Migrate owned particles (no ghosts may be present) to the ranks owning their centres.
  /// `history` holds this rank's contact records; records of migrating particles are sent
  /// along (and kept here too: pairs with a particle that stays still need them).
  void migrate(const Decomposition& dd, ParticleStore& p, HistoryMap& history);
  CommStats stats;
};

/// Exchange variable-length buffers of doubles with the two neighbours along direction d.
/// Sends `to_lo` down and `to_hi` up; returns what came from below in `from_lo`, from above in
/// `from_hi`. Ranks without a neighbour on a side send/receive nothing on it.
void exchange_with_neighbors(const Decomposition& dd, int d, const std::vector<double>& to_lo,
                             const std::vector<double>& to_hi, std::vector<double>& from_lo,
                             std::vector<double>& from_hi, CommStats& stats);

}  // namespace fdem
