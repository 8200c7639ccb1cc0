#pragma once
// Start-up without replicated particles: each rank holds any share of the particles (a block of
// a checkpoint's rows, say) and of the contact records; scatter_to_owners sends every particle to
// the rank owning its centre and every record to the owners of its particles, in two all-to-all
// exchanges plus one through a directory (particle id -> owner, spread over the ranks by id), so
// no rank ever holds more than its share, its owned particles and their records.
#include <cstdint>
#include <vector>

#include "dem/contact_history.hpp"
#include "dem/particles.hpp"
#include "partition/decomposition.hpp"

namespace fdem {

/// Collective. `p` (no ghosts) is this rank's share of the particles: the shares are disjoint
/// over the ranks and together the whole set, split in any way. On return `p` holds the particles
/// this rank owns under `dd`, sorted by id (the order a rebuild gives them). `records` is this
/// rank's share of the contact records (disjoint, any split); on return the records that involve
/// a particle owned here: a particle-particle record (kind 0) at the owners of both its particles,
/// any other at the owner of its particle (`a`). A record naming a particle that does not exist
/// is dropped. The store's arrays are allocated with room for (1 + room) times the particles
/// received (the ghosts to come: Decomposition::ghost_share), so they are not allocated again.
void scatter_to_owners(const Decomposition& dd, ParticleStore& p, std::vector<ContactRecord>& records,
                       double room = 0);

}  // namespace fdem
