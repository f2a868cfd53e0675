// Run output: HDF5 particle snapshots with an XDMF index that ParaView opens as a time
// series, and a CSV time series of global quantities. Every file is written to a temporary
// file and renamed into place (common/atomic_file.h), so a reader (or a crash) never sees half
// a file.
#pragma once

#include "dem/dem_system.h"

#include <string>
#include <vector>

namespace magbrush::dem {

// Writes `text` to `path` atomically (common/atomic_file.h; kept here for the measurements).
void write_file_atomically(const std::string &path, const std::string &text);

class SnapshotWriter
{
public:
  // Snapshots go to <directory>/snapshots/, the index to <directory>/particles.xdmf.
  explicit SnapshotWriter(const std::string &directory);

  // One snapshot: position, velocity, angular_velocity, force (N×3), radius, species, id,
  // contact_count (N), in id order so that ParaView sees each particle at the same index.
  void write(const DemSystem &system);

  // Re-reads the list of snapshots already written (restart continues the index).
  void resume(double up_to_time);

  const std::vector<std::pair<double, std::string>> &snapshots() const { return snapshots_; }

private:
  std::string directory_;
  std::vector<std::pair<double, std::string>> snapshots_; // (time, file relative to directory)
  std::size_t particles_ = 0;
  std::vector<std::size_t> counts_; // particles in each snapshot
  void write_index() const;
};

// CSV time series: step, time, kinetic and rotational energy, particle and wall contacts,
// and for every wall its force (x, y, z) and torque (z).
class TimeSeriesWriter
{
public:
  TimeSeriesWriter(const std::string &path, const DemSystem &system);
  void record(const DemSystem &system);
  // Restart: keeps the rows of an existing file up to `step`.
  void resume(long step);
  void flush() const;

private:
  std::string path_, header_;
  std::vector<std::pair<long, std::string>> rows_;
};

} // namespace magbrush::dem
