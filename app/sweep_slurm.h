// `magbrush sweep ... --emit slurm`: the sweep as a Slurm job array, written, not run.
//
//   sweep_<NAME>.slurm        #SBATCH --array=0-(N-1): task i runs `magbrush sweep ... --point i`
//                             (that one point, its row kept in its folder)
//   sweep_<NAME>_merge.slurm  `magbrush sweep ... --merge`: the table, profiles and plots from
//                             the finished point folders; submitted with --dependency=afterok on
//                             the array, so it starts once every point has succeeded
//
// The resource lines are defaults for the user to edit (partition and account are left
// commented out: they are the cluster's names). The commands name the binary and the case by
// absolute path and the job runs in the folder the sweep was emitted from (--chdir), so that
// relative paths in --set values mean what they meant on the command line.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace magbrush {

struct SlurmSweep
{
  std::string job_name;                   // "sweep_<NAME>"
  std::size_t points = 0;                 // array tasks 0..points-1
  std::string work_dir;                   // absolute: --chdir
  std::string log_dir;                    // absolute: where slurm-*.out go (the sweep's folder)
  std::vector<std::string> point_command; // the sweep's words, without --point (appended here)
  std::vector<std::string> merge_command; // the sweep's words with --merge
  bool threads_given = false;             // else --threads follows the task's --cpus-per-task
};

// The two scripts' text.
std::string slurm_array_script(const SlurmSweep &sweep, const std::string &merge_script_path,
                               const std::string &array_script_path);
std::string slurm_merge_script(const SlurmSweep &sweep);

// A word quoted for bash: as it is when it holds only safe characters, else in single quotes.
std::string shell_quoted(const std::string &word);

} // namespace magbrush
