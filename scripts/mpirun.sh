#!/usr/bin/env bash
# The one place that knows how to call mpirun on this project's machines:
# as root it needs --allow-run-as-root; with more ranks than cores it needs --oversubscribe;
# oversubscribed ranks must yield instead of busy-polling or they starve each other.
# Usage: scripts/mpirun.sh -n P program args...
set -euo pipefail
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_mpi_yield_when_idle=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
# ob1 is the point-to-point layer Debian's Open MPI selects on one machine; naming it skips probing
# the others (0.2 s a start). A cluster's own launcher (srun, the site's mpirun) chooses its fabric.
export OMPI_MCA_pml=${OMPI_MCA_pml:-ob1}
exec mpirun --oversubscribe --bind-to none "$@"
