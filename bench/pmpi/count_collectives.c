/* A PMPI wrapper that counts the collectives of a run by caller (bench/collectives.sh):
 * every MPI_Allreduce / Allgather / Bcast / Barrier is recorded with the return addresses of its
 * callers inside the fdem binary or PETSc (offsets from their load address, for addr2line); rank 0
 * writes "count kind file:offset ..." lines to $PMPI_OUT at MPI_Finalize. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <execinfo.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NKEYS 4096
typedef struct { char key[512]; long n; } Entry;
static Entry table[NKEYS];
static int n_entries;

static void record(const char* kind) {
  void* bt[16];
  const int n = backtrace(bt, 16);
  char key[512];
  int o = snprintf(key, sizeof key, "%s", kind);
  for (int i = 2; i < n && o < (int)sizeof key - 64; ++i) {
    Dl_info d;
    if (!dladdr(bt[i], &d) || !d.dli_fname) continue;
    if (!strstr(d.dli_fname, "fdem") && !strstr(d.dli_fname, "petsc")) continue;
    o += snprintf(key + o, sizeof key - o, " %s:%lx", d.dli_fname, (unsigned long)((char*)bt[i] - (char*)d.dli_fbase) - 1);
  }
  for (int i = 0; i < n_entries; ++i)
    if (!strcmp(table[i].key, key)) { table[i].n++; return; }
  if (n_entries < NKEYS) { strcpy(table[n_entries].key, key); table[n_entries++].n = 1; }
}

int MPI_Allreduce(const void* a, void* b, int c, MPI_Datatype t, MPI_Op op, MPI_Comm comm) {
  record("allreduce");
  return PMPI_Allreduce(a, b, c, t, op, comm);
}
int MPI_Allgather(const void* a, int c, MPI_Datatype t, void* b, int d, MPI_Datatype u, MPI_Comm comm) {
  record("allgather");
  return PMPI_Allgather(a, c, t, b, d, u, comm);
}
int MPI_Bcast(void* a, int c, MPI_Datatype t, int r, MPI_Comm comm) {
  record("bcast");
  return PMPI_Bcast(a, c, t, r, comm);
}
int MPI_Barrier(MPI_Comm comm) {
  record("barrier");
  return PMPI_Barrier(comm);
}
int MPI_Finalize(void) {
  int r = 0;
  PMPI_Comm_rank(MPI_COMM_WORLD, &r);
  const char* out = getenv("PMPI_OUT");
  if (r == 0 && out) {
    FILE* f = fopen(out, "w");
    if (f) {
      for (int i = 0; i < n_entries; ++i) fprintf(f, "%ld %s\n", table[i].n, table[i].key);
      fclose(f);
    }
  }
  return PMPI_Finalize();
}
