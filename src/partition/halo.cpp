#include "partition/halo.hpp"

#include <mpi.h>

#include <unordered_set>

namespace fdem {

namespace {

constexpr int kFull = 18;    // doubles per particle in a full copy
constexpr int kUpdate = 9;   // doubles per particle in a ghost update (x, v, w)
constexpr int kRecord = 10;  // doubles per contact record

void pack_full(const ParticleStore& p, std::size_t i, std::vector<double>& b) {
  const Vec3* vs[4] = {&p.x[i], &p.v[i], &p.w[i], &p.x0[i]};
  for (const Vec3* v : vs) { b.push_back(v->x); b.push_back(v->y); b.push_back(v->z); }
  b.push_back(p.r[i]);
  b.push_back(p.m[i]);
  b.push_back(static_cast<double>(p.id[i]));
  b.push_back(p.mat[i]);
  b.push_back(p.blocked[i]);
  b.push_back(static_cast<double>(p.key[i]));  // < 2^51 (order_key): exact
}

void unpack_full(ParticleStore& p, const double* b) {
  p.push_back({b[0], b[1], b[2]}, {b[3], b[4], b[5]}, {b[6], b[7], b[8]}, b[12], b[13],
              static_cast<std::int64_t>(b[14]), static_cast<std::int32_t>(b[15]),
              static_cast<std::uint8_t>(b[16]), {b[9], b[10], b[11]}, static_cast<std::int64_t>(b[17]));
}

void pack_record(const ContactRecord& r, std::vector<double>& b) {
  b.push_back(static_cast<double>(r.a));
  b.push_back(static_cast<double>(r.b));
  b.push_back(r.kind);
  b.push_back(r.sub);
  b.push_back(r.state.ft.x); b.push_back(r.state.ft.y); b.push_back(r.state.ft.z);
  b.push_back(r.state.rot.x); b.push_back(r.state.rot.y); b.push_back(r.state.rot.z);
}

ContactRecord unpack_record(const double* b) {
  ContactRecord r;
  r.a = static_cast<std::int64_t>(b[0]);
  r.b = static_cast<std::int64_t>(b[1]);
  r.kind = static_cast<std::int32_t>(b[2]);
  r.sub = static_cast<std::int32_t>(b[3]);
  r.state.ft = {b[4], b[5], b[6]};
  r.state.rot = {b[7], b[8], b[9]};
  return r;
}

}  // namespace

void exchange_with_neighbors(const Decomposition& dd, int d, const std::vector<double>& to_lo,
                             const std::vector<double>& to_hi, std::vector<double>& from_lo,
                             std::vector<double>& from_hi, CommStats& stats) {
  const int lo = dd.lo_neighbor[d] >= 0 ? dd.lo_neighbor[d] : MPI_PROC_NULL;
  const int hi = dd.hi_neighbor[d] >= 0 ? dd.hi_neighbor[d] : MPI_PROC_NULL;
  long n_to_lo = static_cast<long>(to_lo.size()), n_to_hi = static_cast<long>(to_hi.size());
  long n_from_lo = 0, n_from_hi = 0;
  // Down: send to lo, receive from hi. Up: send to hi, receive from lo.
  MPI_Sendrecv(&n_to_lo, 1, MPI_LONG, lo, 10 + d, &n_from_hi, 1, MPI_LONG, hi, 10 + d, dd.comm,
               MPI_STATUS_IGNORE);
  MPI_Sendrecv(&n_to_hi, 1, MPI_LONG, hi, 20 + d, &n_from_lo, 1, MPI_LONG, lo, 20 + d, dd.comm,
               MPI_STATUS_IGNORE);
  from_lo.resize(n_from_lo);
  from_hi.resize(n_from_hi);
  MPI_Sendrecv(to_lo.data(), static_cast<int>(n_to_lo), MPI_DOUBLE, lo, 30 + d, from_hi.data(),
               static_cast<int>(n_from_hi), MPI_DOUBLE, hi, 30 + d, dd.comm, MPI_STATUS_IGNORE);
  MPI_Sendrecv(to_hi.data(), static_cast<int>(n_to_hi), MPI_DOUBLE, hi, 40 + d, from_lo.data(),
               static_cast<int>(n_from_lo), MPI_DOUBLE, lo, 40 + d, dd.comm, MPI_STATUS_IGNORE);
  if (lo != MPI_PROC_NULL) { stats.messages += 2; stats.bytes += 8 * (n_to_lo + 1); }
  if (hi != MPI_PROC_NULL) { stats.messages += 2; stats.bytes += 8 * (n_to_hi + 1); }
}

void Halo::exchange(const Decomposition& dd, ParticleStore& p, double cutoff) {
  p.clear_ghosts();
  // Room for the ghosts before they arrive (the last exchange's count, or the ghost layer's share
  // of the subdomain the first time): appended one by one they would regrow the store's arrays,
  // and under Open MPI freed memory stays with the process (docs/performance.md#memory-per-rank).
  const std::size_t expect = ghosts_last_ > 0 ? ghosts_last_
                                              : static_cast<std::size_t>(static_cast<double>(p.n_owned) * dd.ghost_share(cutoff));
  p.make_room(p.n_owned + expect);
  std::vector<double> from_lo, from_hi;
  for (int d = 0; d < 3; ++d) {
    Sweep& s = sweeps_[d];
    s = Sweep{};
    if (dd.dims[d] > 1) {
      const double lo_edge = dd.lo[d] + cutoff, hi_edge = dd.hi[d] - cutoff;
      sbuf_lo_.clear();
      sbuf_hi_.clear();
      const std::size_t n = p.size();
      for (std::size_t i = 0; i < n; ++i) {
        const double c = p.x[i][d];
        if (dd.lo_neighbor[d] >= 0 && c < lo_edge) { s.send_lo.push_back(i); pack_full(p, i, sbuf_lo_); }
        if (dd.hi_neighbor[d] >= 0 && c >= hi_edge) { s.send_hi.push_back(i); pack_full(p, i, sbuf_hi_); }
      }
      exchange_with_neighbors(dd, d, sbuf_lo_, sbuf_hi_, from_lo, from_hi, stats);
      s.recv_lo_begin = p.size();
      s.recv_lo_n = from_lo.size() / kFull;
      p.make_room(p.size() + s.recv_lo_n + from_hi.size() / kFull);
      for (std::size_t k = 0; k < s.recv_lo_n; ++k) unpack_full(p, &from_lo[k * kFull]);
      s.recv_hi_begin = p.size();
      s.recv_hi_n = from_hi.size() / kFull;
      for (std::size_t k = 0; k < s.recv_hi_n; ++k) unpack_full(p, &from_hi[k * kFull]);
    }
  }
  ghosts_last_ = p.n_ghost();
}

void Halo::update(const Decomposition& dd, ParticleStore& p) {
  std::vector<double>& from_lo = rbuf_lo_;
  std::vector<double>& from_hi = rbuf_hi_;
  auto pack = [&](const std::vector<std::size_t>& idx, std::vector<double>& b) {
    b.resize(idx.size() * kUpdate);
    double* o = b.data();
    for (std::size_t i : idx) {
      const Vec3 &x = p.x[i], &v = p.v[i], &w = p.w[i];
      o[0] = x.x; o[1] = x.y; o[2] = x.z; o[3] = v.x; o[4] = v.y; o[5] = v.z;
      o[6] = w.x; o[7] = w.y; o[8] = w.z;
      o += kUpdate;
    }
  };
  auto unpack = [&](const std::vector<double>& b, std::size_t begin, std::size_t n) {
    const double* o = b.data();
    for (std::size_t k = 0; k < n; ++k, o += kUpdate) {
      const std::size_t i = begin + k;
      p.x[i] = {o[0], o[1], o[2]};
      p.v[i] = {o[3], o[4], o[5]};
      p.w[i] = {o[6], o[7], o[8]};
    }
  };
  for (int d = 0; d < 3; ++d) {
    if (dd.dims[d] == 1) continue;
    const Sweep& s = sweeps_[d];
    pack(s.send_lo, sbuf_lo_);
    pack(s.send_hi, sbuf_hi_);
    // Sizes are known from the plan: one message each way, no size exchange.
    from_lo.resize(s.recv_lo_n * kUpdate);
    from_hi.resize(s.recv_hi_n * kUpdate);
    const int lo = dd.lo_neighbor[d] >= 0 ? dd.lo_neighbor[d] : MPI_PROC_NULL;
    const int hi = dd.hi_neighbor[d] >= 0 ? dd.hi_neighbor[d] : MPI_PROC_NULL;
    MPI_Request req[4];
    MPI_Irecv(from_hi.data(), static_cast<int>(from_hi.size()), MPI_DOUBLE, hi, 50 + d, dd.comm, &req[0]);
    MPI_Irecv(from_lo.data(), static_cast<int>(from_lo.size()), MPI_DOUBLE, lo, 60 + d, dd.comm, &req[1]);
    MPI_Isend(sbuf_lo_.data(), static_cast<int>(sbuf_lo_.size()), MPI_DOUBLE, lo, 50 + d, dd.comm, &req[2]);
    MPI_Isend(sbuf_hi_.data(), static_cast<int>(sbuf_hi_.size()), MPI_DOUBLE, hi, 60 + d, dd.comm, &req[3]);
    MPI_Waitall(4, req, MPI_STATUSES_IGNORE);
    if (lo != MPI_PROC_NULL) { stats.messages += 1; stats.bytes += 8 * sbuf_lo_.size(); }
    if (hi != MPI_PROC_NULL) { stats.messages += 1; stats.bytes += 8 * sbuf_hi_.size(); }
    unpack(from_lo, s.recv_lo_begin, s.recv_lo_n);
    unpack(from_hi, s.recv_hi_begin, s.recv_hi_n);
  }
}

void Distributor::migrate(const Decomposition& dd, ParticleStore& p, HistoryMap& history) {
  p.clear_ghosts();
  // Index the records by the particles they involve, once per call.
  std::unordered_multimap<std::int64_t, ContactKey> by_particle;
  auto index_record = [&](const ContactKey& k) {
    by_particle.emplace(k.a, k);
    if (k.kind == 0) by_particle.emplace(k.b, k);
  };
  for (const auto& kv : history) index_record(kv.first);

  std::vector<double> to_lo, to_hi, from_lo, from_hi;
  for (int d = 0; d < 3; ++d) {
    if (dd.dims[d] == 1) continue;
    for (;;) {
      to_lo.clear();
      to_hi.clear();
      std::vector<std::size_t> keep;
      keep.reserve(p.n_owned);
      // Per particle: [kFull particle values][count of records][records...]
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const int s = dd.slab(d, p.x[i][d]);
        std::vector<double>* out = nullptr;
        if (s < dd.coords[d] && dd.lo_neighbor[d] >= 0) out = &to_lo;
        else if (s > dd.coords[d] && dd.hi_neighbor[d] >= 0) out = &to_hi;
        if (!out) { keep.push_back(i); continue; }
        pack_full(p, i, *out);
        const std::size_t count_pos = out->size();
        out->push_back(0);
        auto range = by_particle.equal_range(p.id[i]);
        int count = 0;
        for (auto it = range.first; it != range.second; ++it) {
          auto h = history.find(it->second);
          if (h == history.end()) continue;
          ContactRecord r{it->second.a, it->second.b, it->second.kind, it->second.sub, h->second};
          pack_record(r, *out);
          ++count;
        }
        (*out)[count_pos] = count;
      }
      p.permute_owned(keep);
      p.n_owned = p.size();
      exchange_with_neighbors(dd, d, to_lo, to_hi, from_lo, from_hi, stats);
      int moved_again = 0;
      for (const std::vector<double>* in : {&from_lo, &from_hi}) {
        std::size_t k = 0;
        while (k < in->size()) {
          unpack_full(p, &(*in)[k]);
          k += kFull;
          const int count = static_cast<int>((*in)[k++]);
          for (int c = 0; c < count; ++c, k += kRecord) {
            ContactRecord r = unpack_record(&(*in)[k]);
            ContactKey key = key_of(r);
            if (history.emplace(key, r.state).second) index_record(key);
          }
        }
      }
      p.n_owned = p.size();
      for (std::size_t i = 0; i < p.n_owned; ++i)
        if (dd.slab(d, p.x[i][d]) != dd.coords[d]) moved_again = 1;
      int any = 0;
      MPI_Allreduce(&moved_again, &any, 1, MPI_INT, MPI_MAX, dd.comm);
      if (!any) break;
    }
  }
}

}  // namespace fdem
