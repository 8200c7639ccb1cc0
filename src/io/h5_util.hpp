#pragma once
// Internal helpers for the HDF5 writers/readers in src/io (snapshot.cpp, checkpoint.cpp):
// RAII handles, error checking that throws (never prints/aborts), typed dataset and attribute
// I/O, and the collective "each rank writes its rows at an offset" pattern.
//
// Not part of the public interface: include only from src/io/*.cpp.
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "base/vec3.hpp"

namespace fdem::h5 {

static_assert(sizeof(Vec3) == 3 * sizeof(double) && std::is_standard_layout_v<Vec3>,
              "Vec3 must be three packed doubles for direct HDF5 I/O");

/// Owns one HDF5 identifier; closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer c) : id_(id), close_(c) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) { reset(); id_ = o.id_; close_ = o.close_; o.id_ = -1; }
    return *this;
  }
  ~Handle() { reset(); }
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }  // NOLINT: convenience in H5 calls
  /// Close now; returns the close status (>= 0 on success, also when nothing was open).
  herr_t close() {
    herr_t s = 0;
    if (id_ >= 0 && close_) s = close_(id_);
    id_ = -1;
    return s;
  }

 private:
  void reset() { if (id_ >= 0 && close_) close_(id_); id_ = -1; }
  hid_t id_ = -1;
  Closer close_ = nullptr;
};

/// Turns off HDF5's automatic error-stack printing for its lifetime (restores it afterwards):
/// failures are reported by exceptions carrying the file name instead.
class Quiet {
 public:
  Quiet() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// The file of an output series at a step: <prefix>_<step, 8 digits>.h5.
inline std::string step_file_name(const std::string& prefix, std::int64_t step) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "_%08lld.h5", static_cast<long long>(step));
  return prefix + buf;
}

/// A double written so that it reads back exactly (XDMF times and coordinates).
inline std::string exact(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// The files of an output series in dir -- names exactly step_file_name(prefix, s) -- with step
/// s <= max_step, as (step, path) pairs in directory order (a restart adopts them). A missing or
/// unreadable directory gives none.
inline std::vector<std::pair<std::int64_t, std::filesystem::path>> step_files(const std::string& dir,
                                                                              const std::string& prefix,
                                                                              std::int64_t max_step) {
  std::vector<std::pair<std::int64_t, std::filesystem::path>> out;
  std::error_code ec;
  const std::string pre = prefix + "_", suf = ".h5";
  for (const auto& de : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = de.path().filename().string();
    if (name.size() <= pre.size() + suf.size() || name.compare(0, pre.size(), pre) != 0 ||
        name.compare(name.size() - suf.size(), suf.size(), suf) != 0)
      continue;
    const std::string num = name.substr(pre.size(), name.size() - pre.size() - suf.size());
    char* end = nullptr;
    const long long s = std::strtoll(num.c_str(), &end, 10);
    if (end == num.c_str() || *end != '\0' || s > max_step || name != step_file_name(prefix, s)) continue;
    out.emplace_back(s, de.path());
  }
  return out;
}

/// The innermost message of the current HDF5 error stack ("" if none).
inline std::string last_error() {
  std::string msg;
  auto cb = [](unsigned n, const H5E_error2_t* e, void* d) -> herr_t {
    auto* s = static_cast<std::string*>(d);
    // Walking upward, frame 0 is the innermost (most specific) error; fall back to the first
    // frame that has a description.
    if (e && e->desc && (n == 0 || s->empty())) *s = e->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, cb, &msg);
  return msg;
}

/// Throws std::runtime_error "<file>: HDF5 error: <what> (<innermost HDF5 message>)".
[[noreturn]] inline void fail(const std::string& file, const std::string& what) {
  std::string m = file + ": HDF5 error: " + what;
  const std::string h = last_error();
  if (!h.empty()) m += " (" + h + ")";
  throw std::runtime_error(m);
}

inline hid_t check(hid_t id, const std::string& file, const std::string& what) {
  if (id < 0) fail(file, what);
  return id;
}
inline void check_status(herr_t s, const std::string& file, const std::string& what) {
  if (s < 0) fail(file, what);
}

// ---- type mapping (memory type, file type) ----
/// Write a text file next to its target and rename it into place, so that a viewer polling the
/// file never sees half of it. Throws std::runtime_error naming the file.
inline void write_text_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw std::runtime_error(tmp + ": cannot open for writing");
    f << text;
    f.flush();
    if (!f) throw std::runtime_error(tmp + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot rename " + tmp + ": " + ec.message());
}

/// Run `fn` on rank 0 only (e.g. writing a sidecar file) and make every rank throw if it
/// failed: rank 0 with its own message, the others with `what_others`. Collective.
template <class F>
void on_rank0_or_throw(MPI_Comm comm, F&& fn, const std::string& what_others) {
  int rank = 0, ok = 1;
  MPI_Comm_rank(comm, &rank);
  std::string err;
  if (rank == 0) {
    try {
      fn();
    } catch (const std::exception& ex) {
      ok = 0;
      err = ex.what();
    }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, comm);
  if (!ok) throw std::runtime_error(rank == 0 ? err : what_others);
}

template <class T> struct Type;
template <> struct Type<double> {
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
  static hid_t file() { return H5T_IEEE_F64LE; }
};
template <> struct Type<std::int64_t> {
  static hid_t mem() { return H5T_NATIVE_INT64; }
  static hid_t file() { return H5T_STD_I64LE; }
};
template <> struct Type<std::int32_t> {
  static hid_t mem() { return H5T_NATIVE_INT32; }
  static hid_t file() { return H5T_STD_I32LE; }
};
template <> struct Type<std::uint8_t> {
  static hid_t mem() { return H5T_NATIVE_UINT8; }
  static hid_t file() { return H5T_STD_U8LE; }
};

// ---- files ----

/// Collective create (truncate) with the MPI-IO driver. `checksummed`: the file format of HDF5
/// 1.8 and later, whose superblock, object headers (attributes included) and chunk indexes carry
/// checksums that H5Fopen / H5Dopen verify (checkpoints and specimens; see write_rows for the
/// data itself).
inline Handle create_parallel(const std::string& path, MPI_Comm comm, bool checksummed = false) {
  Handle fapl(check(H5Pcreate(H5P_FILE_ACCESS), path, "H5Pcreate(fapl)"), H5Pclose);
  // The collective-write aggregator's buffer: 4 MiB instead of Open MPI's 32 MiB, which was the
  // largest single item on rank 0 of a 1 M-grain run on 4 ranks (docs/performance.md#memory-per-rank);
  // FDEM_CB_BUFFER_SIZE (bytes) sets another.
  MPI_Info info;
  MPI_Info_create(&info);
  const char* cb = std::getenv("FDEM_CB_BUFFER_SIZE");
  MPI_Info_set(info, "cb_buffer_size", cb && *cb ? cb : "4194304");
  check_status(H5Pset_fapl_mpio(fapl, comm, info), path, "H5Pset_fapl_mpio");
  MPI_Info_free(&info);
  if (checksummed)
    check_status(H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_LATEST), path, "H5Pset_libver_bounds");
  hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  if (f < 0) fail(path, "cannot create file");
  return Handle(f, H5Fclose);
}

/// Collective-write transfer property list.
inline Handle collective_dxpl(const std::string& path) {
  Handle dxpl(check(H5Pcreate(H5P_DATASET_XFER), path, "H5Pcreate(dxpl)"), H5Pclose);
  check_status(H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE), path, "H5Pset_dxpl_mpio");
  return dxpl;
}

inline Handle create_group(hid_t loc, const char* name, const std::string& path) {
  hid_t g = H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) fail(path, std::string("cannot create group ") + name);
  return Handle(g, H5Gclose);
}

// ---- collective row-distributed writes ----

/// Where this rank's rows go: offset (exclusive prefix sum) and the global count.
struct RowRange {
  hsize_t offset = 0, total = 0, local = 0;
};
inline RowRange row_range(std::size_t n_local, MPI_Comm comm) {
  long long n = static_cast<long long>(n_local), off = 0, tot = 0;
  MPI_Exscan(&n, &off, 1, MPI_LONG_LONG, MPI_SUM, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) off = 0;  // MPI_Exscan leaves rank 0's result undefined
  MPI_Allreduce(&n, &tot, 1, MPI_LONG_LONG, MPI_SUM, comm);
  return {static_cast<hsize_t>(off), static_cast<hsize_t>(tot), static_cast<hsize_t>(n)};
}

/// Collective: create dataset `name` (total x cols, or 1-D if cols == 1) and write this
/// rank's `rows.local` rows (row-major, `cols` values each) at `rows.offset`.
/// Ranks with no rows take part with empty selections. `checksum`: chunked, with HDF5's
/// Fletcher32 filter (a checksum per chunk, verified by every H5Dread; checkpoints and
/// specimens); empty datasets stay contiguous (no data to check).
template <class T>
void write_rows(hid_t loc, const char* name, const T* data, hsize_t cols, const RowRange& rows,
                hid_t dxpl, const std::string& path, bool checksum = false) {
  const int nd = cols > 1 ? 2 : 1;
  const hsize_t fdims[2] = {rows.total, cols};
  Handle fspace(check(H5Screate_simple(nd, fdims, nullptr), path, "H5Screate_simple"),
                H5Sclose);
  Handle dcpl(check(H5Pcreate(H5P_DATASET_CREATE), path, "H5Pcreate(dcpl)"), H5Pclose);
  if (checksum && rows.total > 0) {
    // chunks of up to 2^16 values (512 KiB of doubles), of equal size (the last chunk is
    // stored whole, so the file grows by less than one row per chunk)
    const hsize_t max_rows = std::max<hsize_t>(1, 65536 / cols);
    const hsize_t n_chunks = (rows.total + max_rows - 1) / max_rows;
    const hsize_t chunk[2] = {(rows.total + n_chunks - 1) / n_chunks, cols};
    check_status(H5Pset_chunk(dcpl, nd, chunk), path, "H5Pset_chunk");
    check_status(H5Pset_fletcher32(dcpl), path, "H5Pset_fletcher32");
  }
  Handle dset(H5Dcreate2(loc, name, Type<T>::file(), fspace, H5P_DEFAULT, dcpl,
                         H5P_DEFAULT), H5Dclose);
  if (dset.get() < 0) fail(path, std::string("cannot create dataset ") + name);
  if (rows.total == 0) return;  // same on every rank: nothing to write
  const hsize_t mdims[2] = {std::max<hsize_t>(rows.local, 1), cols};
  Handle mspace(check(H5Screate_simple(nd, mdims, nullptr), path, "H5Screate_simple"),
                H5Sclose);
  T dummy{};
  const void* buf = data;
  if (rows.local == 0) {
    check_status(H5Sselect_none(fspace), path, "H5Sselect_none");
    check_status(H5Sselect_none(mspace), path, "H5Sselect_none");
    buf = &dummy;
  } else {
    const hsize_t start[2] = {rows.offset, 0}, count[2] = {rows.local, cols};
    check_status(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr),
                 path, "H5Sselect_hyperslab");
  }
  if (H5Dwrite(dset, Type<T>::mem(), mspace, fspace, dxpl, buf) < 0)
    fail(path, std::string("cannot write dataset ") + name);
}

template <class T>
void write_rows(hid_t loc, const char* name, const std::vector<T>& v, const RowRange& rows,
                hid_t dxpl, const std::string& path, bool checksum = false) {
  write_rows<T>(loc, name, v.data(), 1, rows, dxpl, path, checksum);
}
inline void write_rows(hid_t loc, const char* name, const std::vector<Vec3>& v,
                       const RowRange& rows, hid_t dxpl, const std::string& path,
                       bool checksum = false) {
  write_rows<double>(loc, name, reinterpret_cast<const double*>(v.data()), 3, rows, dxpl, path,
                     checksum);
}

// ---- attributes (collective in parallel files: every rank writes the same value) ----

template <class T>
void write_attr(hid_t loc, const char* name, T value, const std::string& path) {
  Handle space(check(H5Screate(H5S_SCALAR), path, "H5Screate"), H5Sclose);
  Handle a(H5Acreate2(loc, name, Type<T>::file(), space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.get() < 0) fail(path, std::string("cannot create attribute ") + name);
  check_status(H5Awrite(a, Type<T>::mem(), &value), path,
               std::string("cannot write attribute ") + name);
}

inline void write_attr_string(hid_t loc, const char* name, const std::string& value,
                              const std::string& path) {
  Handle type(check(H5Tcopy(H5T_C_S1), path, "H5Tcopy"), H5Tclose);
  check_status(H5Tset_size(type, std::max<std::size_t>(value.size(), 1)), path, "H5Tset_size");
  check_status(H5Tset_strpad(type, H5T_STR_NULLPAD), path, "H5Tset_strpad");
  Handle space(check(H5Screate(H5S_SCALAR), path, "H5Screate"), H5Sclose);
  Handle a(H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.get() < 0) fail(path, std::string("cannot create attribute ") + name);
  std::string buf = value.empty() ? std::string(1, '\0') : value;
  check_status(H5Awrite(a, type, buf.data()), path, std::string("cannot write attribute ") + name);
}

// ---- reading (whole datasets; errors reported through a callback that throws) ----

/// Reads scalar attribute `name`; false if missing or unreadable as T.
template <class T>
bool read_attr(hid_t loc, const char* name, T& out) {
  if (H5Aexists(loc, name) <= 0) return false;
  Handle a(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose);
  if (a.get() < 0) return false;
  Handle space(H5Aget_space(a), H5Sclose);
  if (space.get() < 0 || H5Sget_simple_extent_npoints(space) != 1) return false;
  return H5Aread(a, Type<T>::mem(), &out) >= 0;
}

/// Reads a fixed- or variable-length string attribute; false if missing or not a string.
inline bool read_attr_string(hid_t loc, const char* name, std::string& out) {
  if (H5Aexists(loc, name) <= 0) return false;
  Handle a(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose);
  if (a.get() < 0) return false;
  Handle ftype(H5Aget_type(a), H5Tclose);
  if (ftype.get() < 0 || H5Tget_class(ftype) != H5T_STRING) return false;
  Handle space(H5Aget_space(a), H5Sclose);
  if (space.get() < 0 || H5Sget_simple_extent_npoints(space) != 1) return false;
  if (H5Tis_variable_str(ftype) > 0) {
    Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mtype, H5T_VARIABLE);
    char* s = nullptr;
    if (H5Aread(a, mtype, &s) < 0) return false;
    out = s ? s : "";
    H5free_memory(s);
    return true;
  }
  const std::size_t n = H5Tget_size(ftype);
  std::vector<char> buf(n + 1, '\0');
  // Read with the file's own padding and size (a NULLTERM memory type of the same size would
  // drop the last character of a NULLPAD string); buf has room for a terminator.
  if (H5Aread(a, ftype, buf.data()) < 0) return false;
  out.assign(buf.data());  // stops at the first NUL (null-padded / null-terminated)
  return true;
}

/// Opens `path` read-only (serial driver) for a reader of fdem's own files. On failure returns
/// an invalid handle and sets `why`: "not an HDF5 file" when the HDF5 signature is missing, else
/// that HDF5 cannot read it (truncated or corrupted), with HDF5's innermost message.
inline Handle open_read(const std::string& path, std::string& why) {
  {
    std::ifstream f(path, std::ios::binary);
    char sig[8] = {};
    f.read(sig, 8);
    static const char kSig[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
    if (!f || !std::equal(sig, sig + 8, kSig)) {
      why = "not an HDF5 file";
      return Handle();
    }
  }
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) {
    const std::string h = last_error();
    why = "HDF5 cannot open it: the file is truncated or corrupted" + (h.empty() ? std::string() : " (" + h + ")");
    return Handle();
  }
  return Handle(id, H5Fclose);
}

/// True if the link `name` (may contain '/') exists below loc, checking each component.
inline bool exists(hid_t loc, const std::string& name) {
  std::size_t pos = 0;
  while (true) {
    pos = name.find('/', pos + 1);
    const std::string part = name.substr(0, pos);
    if (H5Lexists(loc, part.c_str(), H5P_DEFAULT) <= 0) return false;
    if (pos == std::string::npos) return true;
  }
}

/// Which rows of a dataset a reader takes: part `part` of `parts` equal contiguous blocks
/// (rows [n part / parts, n (part + 1) / parts)); {0, 1} is the whole dataset. A window of the
/// part -- its rows [skip, skip + limit) -- reads it in pieces.
struct RowShare {
  int part = 0, parts = 1;
  hsize_t skip = 0, limit = ~hsize_t{0};
  hsize_t part_first(hsize_t n) const { return n * static_cast<hsize_t>(part) / static_cast<hsize_t>(parts); }
  hsize_t part_end(hsize_t n) const { return n * static_cast<hsize_t>(part + 1) / static_cast<hsize_t>(parts); }
  hsize_t first(hsize_t n) const { return std::min(part_end(n), part_first(n) + std::min(skip, part_end(n))); }
  hsize_t end(hsize_t n) const { return first(n) + std::min(limit, part_end(n) - first(n)); }
};

/// Reads the dataset `name` (rows x cols; cols == 1 means 1-D) into `out`: the whole of it, or
/// the rows of `share` (a hyperslab: only those rows are read). `nrows` is the dataset's row
/// count (all of it). Returns an error message ("" on success).
template <class T>
std::string read_rows(hid_t loc, const std::string& name, hsize_t cols, std::vector<T>& out,
                      hsize_t& nrows, const RowShare& share = {}) {
  if (!exists(loc, name)) return "missing dataset " + name;
  Handle d(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.get() < 0) return "cannot open dataset /" + name + " (the file is corrupted or truncated)";
  Handle space(H5Dget_space(d), H5Sclose);
  if (space.get() < 0) return "cannot read the shape of dataset " + name;
  const int nd = H5Sget_simple_extent_ndims(space);
  hsize_t dims[2] = {0, 0};
  if (nd != (cols > 1 ? 2 : 1) || H5Sget_simple_extent_dims(space, dims, nullptr) < 0 ||
      (cols > 1 && dims[1] != cols))
    return "dataset " + name + " has the wrong shape (expected N x " + std::to_string(cols) + ")";
  nrows = dims[0];
  const hsize_t first = share.first(nrows), count = share.end(nrows) - first;
  out.resize(static_cast<std::size_t>(count * cols));
  if (count == 0) return "";
  herr_t st = 0;
  if (count == nrows) {
    st = H5Dread(d, Type<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  } else {
    const hsize_t start[2] = {first, 0}, block[2] = {count, cols};
    Handle mem(H5Screate_simple(nd, block, nullptr), H5Sclose);
    if (mem.get() < 0 || H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, block, nullptr) < 0)
      return "cannot select rows of dataset " + name;
    st = H5Dread(d, Type<T>::mem(), mem, space, H5P_DEFAULT, out.data());
  }
  if (st < 0) {
    // A dataset with the Fletcher32 filter fails to read when a chunk's checksum does not match.
    Handle dcpl(H5Dget_create_plist(d), H5Pclose);
    unsigned flags = 0;
    std::size_t nelem = 0;
    if (dcpl.get() >= 0 &&
        H5Pget_filter_by_id2(dcpl, H5Z_FILTER_FLETCHER32, &flags, &nelem, nullptr, 0, nullptr, nullptr) >= 0)
      return "checksum mismatch in dataset /" + name + " (the file is corrupted)";
    return "cannot read dataset /" + name + " (the file is corrupted or truncated)";
  }
  return "";
}

}  // namespace fdem::h5
