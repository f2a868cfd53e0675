#include "app/sweep_ranks.h"

#include <mpi.h>

#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

extern char **environ;

namespace magbrush {

namespace {

// The variables through which a launcher tells a process that it is a rank of its job.
bool is_launcher_variable(const std::string &name)
{
  // Kept: a root user's consent to run OpenMPI, which a nested mpirun needs as well.
  if (name == "OMPI_ALLOW_RUN_AS_ROOT" || name == "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM")
    return false;
  for (const char *prefix : {"OMPI_", "PMIX_", "PMI_", "MPI_LOCAL", "HYDRA_"})
    if (name.rfind(prefix, 0) == 0)
      return true;
  return false;
}

// Removes them from this process's environment, so that the programs it starts are not taken
// for ranks of the sweep's job (see sweep_ranks.h).
void forget_launcher_variables()
{
  std::vector<std::string> names;
  for (char **e = environ; *e != nullptr; ++e)
  {
    const std::string entry = *e;
    const std::string name = entry.substr(0, entry.find('='));
    if (is_launcher_variable(name))
      names.push_back(name);
  }
  for (const auto &name : names)
    unsetenv(name.c_str());
}

} // namespace

int rank_of_point(std::size_t point, int ranks)
{
  const std::size_t k = static_cast<std::size_t>(std::max(ranks, 1));
  const std::size_t round = point / k, place = point % k;
  return static_cast<int>(round % 2 == 0 ? place : k - 1 - place);
}

bool launched_by_mpi()
{
  for (const char *v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v) != nullptr)
      return true;
  return false;
}

SweepRanks::SweepRanks()
{
  if (!launched_by_mpi())
    return;
  int already = 0;
  MPI_Initialized(&already);
  if (!already)
    MPI_Init(nullptr, nullptr);
  started_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  // The ranks sharing this node's memory are the ranks sharing its cores.
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &ranks_on_node_);
  MPI_Comm_free(&node);
  forget_launcher_variables();
}

SweepRanks::~SweepRanks()
{
  if (!started_)
    return;
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized)
    MPI_Finalize();
}

int SweepRanks::threads_per_rank() const
{
  if (!started_)
    return 0;
  cpu_set_t set;
  CPU_ZERO(&set);
  const int allowed = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 0;
  const int node_cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int share = std::max(1, node_cores / std::max(1, ranks_on_node_));
  return std::max(1, allowed > 0 ? std::min(allowed, share) : share);
}

int SweepRanks::sum_over_ranks(int value) const
{
  if (!started_)
    return value;
  int sum = 0;
  MPI_Allreduce(&value, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return sum;
}

} // namespace magbrush
