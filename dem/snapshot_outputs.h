// The particle snapshots a run writes, as the case asks (output.xdmf: HDF5 + XDMF,
// snapshot_writer.h; output.vtu: VTK XML + a ParaView collection, vtu_snapshot_writer.h).
#pragma once

#include "dem/snapshot_writer.h"
#include "dem/vtu_snapshot_writer.h"

#include "case/case_model.h"

#include <optional>
#include <string>

namespace magbrush::dem {

class SnapshotOutputs
{
public:
  SnapshotOutputs(const std::string &directory, const OutputSettings &output)
  {
    if (output.xdmf)
      xdmf_.emplace(directory);
    if (output.vtu)
      vtu_.emplace(directory);
  }
  void write(const DemSystem &system)
  {
    if (xdmf_)
      xdmf_->write(system);
    if (vtu_)
      vtu_->write(system);
  }
  void resume(double up_to_time)
  {
    if (xdmf_)
      xdmf_->resume(up_to_time);
    if (vtu_)
      vtu_->resume(up_to_time);
  }

private:
  std::optional<SnapshotWriter> xdmf_;
  std::optional<VtuSnapshotWriter> vtu_;
};

} // namespace magbrush::dem
