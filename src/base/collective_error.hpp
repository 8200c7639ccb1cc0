#pragma once
// Input errors found on some ranks only (a rank reading its share of a file meets a bad row the
// others never see): every rank must throw, with one message, so that it is printed once and no
// rank waits in a collective the others left.
#include <mpi.h>

#include <optional>
#include <string>

#include "base/errors.hpp"

namespace fdem {

/// Collective. `mine` is this rank's error, if it has one. If any rank has one, every rank throws
/// the InputError of the lowest such rank; otherwise returns.
inline void agree_on_input_error(const std::optional<InputError>& mine, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int me = mine ? rank : size, first = size;
  MPI_Allreduce(&me, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return;
  std::string file, why;
  int line = 0;
  if (mine && rank == first) {
    file = mine->file();
    line = mine->line();
    why = std::string(mine->what()).substr(InputError::format(file, line, "").size());
  }
  for (std::string* s : {&file, &why}) {
    int len = static_cast<int>(s->size());
    MPI_Bcast(&len, 1, MPI_INT, first, comm);
    s->resize(static_cast<std::size_t>(len));
    MPI_Bcast(s->data(), len, MPI_CHAR, first, comm);
  }
  MPI_Bcast(&line, 1, MPI_INT, first, comm);
  throw InputError(file, line, why);
}

}  // namespace fdem
