// The points of `magbrush sweep` dealt to the ranks of an MPI job: `mpirun -np K magbrush
// sweep ...` deals the points in rounds of K, forwards in even rounds and backwards in odd ones
// (K = 2: points 0, 3, 4, 7, ... on rank 0 and 1, 2, 5, 6, ... on rank 1). The deal is
// deterministic (the same point always lands on the same rank, whatever the run times); going
// back and forth balances the ranks when the cost grows along the varied values, which is the
// rule for a study (a wider blade gap, a deeper slab, a smaller bead: more particles), where
// dealing i mod K gives the last rank the dearest point of every round. Each rank runs its
// points' pipelines one after the other, then rank 0 alone writes the table once every rank has
// finished.
//
// MPI is started only when the process was launched by an MPI launcher (mpirun/mpiexec/srun
// set their variables in the environment); a plain `magbrush sweep` never touches MPI and runs
// as one rank of one.
//
// Children of a rank: the pipeline starts programs (magbrush-dem, magbrush-field — itself an
// MPI program — and `mpirun -np N magbrush-field` for a parallel field solve). With OpenMPI a
// child that inherits the rank's launcher variables (OMPI_*, PMIX_*) takes itself for a rank of
// the sweep's job and fails in MPI_Init, and a nested mpirun fails the same way. Once MPI is up
// those variables are therefore removed from this process's environment (MPI_Init has read
// them), so that each child starts as a job of its own: magbrush-field as a singleton, a
// nested mpirun as a fresh job. Both measured to work with OpenMPI 4.1 (docs/design.md).
#pragma once

#include <cstddef>

namespace magbrush {

// The rank that runs point `point` of a sweep on `ranks` ranks: rounds of `ranks` points, dealt
// forwards in even rounds and backwards in odd ones.
int rank_of_point(std::size_t point, int ranks);

class SweepRanks
{
public:
  // Starts MPI when launched by an MPI launcher; otherwise one rank of one.
  SweepRanks();
  ~SweepRanks(); // MPI_Finalize when started here
  SweepRanks(const SweepRanks &) = delete;
  SweepRanks &operator=(const SweepRanks &) = delete;

  bool distributed() const { return started_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  // Does this rank run point `point` of the sweep (the deal above)?
  bool owns(std::size_t point) const { return rank_of_point(point, size_) == rank_; }

  // The DEM threads of this rank when the user gave none: its share of the node's cores,
  // min(cores this rank may run on, cores of the node / ranks on the node). The affinity set
  // honours the launcher's binding (mpirun binds each rank to one core by default at -np 2:
  // then one thread; --bind-to none or --map-by slot:PE=N gives more), the division keeps K
  // ranks on one node from each starting one thread per core. 0 when not distributed (the
  // engine's own default: dem.threads, then all cores).
  int threads_per_rank() const;

  // Waits for every rank; returns the sum over the ranks of `value` (e.g. failed points).
  int sum_over_ranks(int value) const;

private:
  bool started_ = false;
  int rank_ = 0;
  int size_ = 1;
  int ranks_on_node_ = 1;
};

// Was this process started by an MPI launcher (OpenMPI, MPICH/Hydra, Slurm's PMI)?
bool launched_by_mpi();

} // namespace magbrush
