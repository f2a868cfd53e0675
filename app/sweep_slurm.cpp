#include "app/sweep_slurm.h"

#include <sstream>

namespace magbrush {

std::string shell_quoted(const std::string &word)
{
  static const std::string safe = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.,/=:+@%";
  if (!word.empty() && word.find_first_not_of(safe) == std::string::npos)
    return word;
  std::string quoted = "'";
  for (char ch : word)
    quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return quoted + "'";
}

namespace {

std::string command_line(const std::vector<std::string> &words)
{
  std::string line;
  for (const auto &w : words)
    line += (line.empty() ? "" : " ") + shell_quoted(w);
  return line;
}

// The lines every script of the sweep shares: its name, where it runs, the cluster's names to fill in.
void common_header(std::ostream &o, const SlurmSweep &s)
{
  o << "#SBATCH --chdir=" << s.work_dir << "\n"
    << "#SBATCH --ntasks=1\n"
    << "# The cluster's names, when it needs them (remove one '#' to use):\n"
    << "##SBATCH --partition=PARTITION\n"
    << "##SBATCH --account=ACCOUNT\n";
}

} // namespace

std::string slurm_array_script(const SlurmSweep &s, const std::string &merge_script_path,
                               const std::string &array_script_path)
{
  std::ostringstream o;
  o << "#!/bin/bash\n"
    << "# " << s.job_name << ": one Slurm array task per point of the sweep (" << s.points << " points),\n"
    << "# written by `magbrush sweep ... --emit slurm`. Submit it, then the merge once every point succeeded:\n"
    << "#   jid=$(sbatch --parsable " << shell_quoted(array_script_path) << ") && sbatch --dependency=afterok:$jid "
    << shell_quoted(merge_script_path) << "\n"
    << "# Edit the resource lines to the cluster and to the case (one point's DEM runs on the task's cores).\n"
    << "#SBATCH --job-name=" << s.job_name << "\n"
    << "#SBATCH --array=0-" << (s.points == 0 ? 0 : s.points - 1) << "\n"
    << "#SBATCH --cpus-per-task=4\n"
    << "#SBATCH --mem=8G\n"
    << "#SBATCH --time=04:00:00\n"
    << "#SBATCH --output=" << s.log_dir << "/slurm-%A_%a.out\n";
  common_header(o, s);
  o << "set -euo pipefail\n"
    << "exec " << command_line(s.point_command) << " --point \"$SLURM_ARRAY_TASK_ID\"";
  if (!s.threads_given)
    o << " --threads \"${SLURM_CPUS_PER_TASK:-1}\"";
  o << "\n";
  return o.str();
}

std::string slurm_merge_script(const SlurmSweep &s)
{
  std::ostringstream o;
  o << "#!/bin/bash\n"
    << "# " << s.job_name << ", merge step: sweep_summary.csv, sweep_profiles.csv and the plots from the\n"
    << "# finished point folders. Submit with --dependency=afterok:<the array's job id> (see "
    << s.job_name << ".slurm).\n"
    << "#SBATCH --job-name=" << s.job_name << "_merge\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --mem=2G\n"
    << "#SBATCH --time=00:30:00\n"
    << "#SBATCH --output=" << s.log_dir << "/slurm-%j-merge.out\n";
  common_header(o, s);
  o << "set -euo pipefail\n"
    << "exec " << command_line(s.merge_command) << "\n";
  return o.str();
}

} // namespace magbrush
