// Particle snapshots as VTK XML unstructured grids (snapshots/particles_<step>.vtu, one vertex
// per particle) with a ParaView collection file particles.pvd that orders them in time — for
// users whose tools read VTK but not XDMF (output.vtu). The point data are those of the HDF5
// snapshots (snapshot_writer.h): velocity, angular velocity, force, radius, charge, species, id,
// contact count, with the particles in the order of their ids. Every file is written atomically.
#pragma once

#include "dem/dem_system.h"

#include <string>
#include <vector>

namespace magbrush::dem {

class VtuSnapshotWriter
{
public:
  explicit VtuSnapshotWriter(const std::string &directory);
  void write(const DemSystem &system);
  // Re-reads the collection written so far, keeping the snapshots not later than the restart.
  void resume(double up_to_time);

  const std::vector<std::pair<double, std::string>> &snapshots() const { return snapshots_; }

private:
  std::string directory_;
  std::vector<std::pair<double, std::string>> snapshots_; // (time, file relative to directory)
  void write_collection() const;
};

} // namespace magbrush::dem
