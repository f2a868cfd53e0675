// The production field stage, `magbrush-field CASE`: from the case to the stored field grids
// (HDF5, with the case hash), the ParaView files and the sleeve flux profile. Each field is
// regenerated only when the inputs it depends on changed (case/case_hash.h).
#pragma once

#include "case/case_model.h"
#include "fields/field_files.h"

#include <mpi.h>

#include <string>
#include <vector>

namespace magbrush::field {

struct FieldRunOptions
{
  bool magnetic = true;
  bool electric = true;
  bool force = false; // regenerate even when the stored field is up to date
  bool vtu = true;
};

// Output paths: field_files.h.

// Returns true if the magnetic field was (re)computed, false if it was up to date.
bool compute_magnetic_field(const Case &c, const FieldRunOptions &options, MPI_Comm comm);
bool compute_electric_field(const Case &c, const FieldRunOptions &options, MPI_Comm comm);

// Element counts derived from the case's mesh sizes (see the .cpp for the rule).
struct RollerDiscretisation;
RollerDiscretisation roller_discretisation(const Case &c);
struct NipDiscretisation;
struct NipLayout;
NipDiscretisation nip_discretisation(const Case &c, const NipLayout &layout);

} // namespace magbrush::field
