#pragma once
// Output of the micro-mechanics measurements (docs/user-guide.md, "Measurements"):
//   measure.csv        one row per box per measurement: step, time, box (index), stress
//                      (6, Pa, compression positive), p, q, Z, Z_mech, porosity, fabric (6),
//                      mean displacement (3), particles, contacts
//   measure_boxes.csv  box index, name, min, max (written once)
//   roses.csv          one row per rose per bin: step, time, rose (index), bin, theta_min,
//                      theta_max (degrees), count, mean normal force (N)
//   measure_<step>.h5  (grid, force network or particle displacements requested)
//                      /grid/*: cell fields; /force_network/*: segments; /particles/*
//   measure_grid.xdmf, force_network.xdmf: temporal collections for ParaView.
#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "dem/measure.hpp"
#include "io/csv.hpp"

namespace fdem {

class MeasureWriter {
 public:
  /// `dir` must exist. `append`: continue the files of a restarted run (rows after
  /// `keep_up_to` dropped, HDF5 files of earlier steps kept listed).
  MeasureWriter(const std::string& dir, const MeasureSpec& spec, MPI_Comm comm, bool append = false,
                double keep_up_to = 0);
  /// Collective.
  void write(const MeasureResult& r);

 private:
  void write_h5(const MeasureResult& r, const std::string& file);
  void write_xdmf() const;
  std::string dir_;
  MeasureSpec spec_;
  MPI_Comm comm_;
  int rank_ = 0;
  std::unique_ptr<CsvWriter> csv_, roses_;
  struct Entry { std::int64_t step; double time; std::int64_t segments; std::string file; };
  std::vector<Entry> entries_;
};

}  // namespace fdem
